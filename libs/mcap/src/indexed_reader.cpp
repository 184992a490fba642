// Footer -> summary section -> chunk indexes -> only the chunks a span needs.
#include "fahr/mcap/indexed_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <utility>

#include "compression.h"

namespace fahr::mcap {
namespace {

// Footer record: opcode, length 20, summary_start, summary_offset_start, summary_crc.
constexpr std::uint64_t kFooterRecord = 1 + 8 + 8 + 8 + 4;
// The largest chunk (compressed or not) accepted: a damaged index cannot
// make the reader allocate more.
constexpr std::uint64_t kMaxChunkBytes = 1ull << 31;

}  // namespace

IndexedReader::IndexedReader(const std::string& path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    error_ = "cannot open " + path + ": " + std::strerror(errno);
    return;
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0 ||
      st.st_size < static_cast<off_t>(2 * sizeof(kMagic) + kFooterRecord)) {
    error_ = path + " is too short to be an MCAP file";
    return;
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  std::vector<std::uint8_t> tail;
  if (!pread_exact(size_ - sizeof(kMagic) - kFooterRecord, sizeof(kMagic) + kFooterRecord, tail) ||
      std::memcmp(tail.data() + kFooterRecord, kMagic, sizeof(kMagic)) != 0 ||
      tail[0] != static_cast<std::uint8_t>(Opcode::kFooter)) {
    error_ = path + " has no footer (a torn recording: fahr_mcap recover rebuilds it)";
    return;
  }
  Decoder footer(std::span<const std::uint8_t>(tail).subspan(9, 20));
  const std::uint64_t summary_start = footer.u64();
  const std::uint64_t footer_start = size_ - sizeof(kMagic) - kFooterRecord;
  if (summary_start == 0 || summary_start >= footer_start) {
    error_ = path + " has no summary section to seek with";
    return;
  }
  std::vector<std::uint8_t> summary;
  if (!pread_exact(summary_start, footer_start - summary_start, summary)) {
    error_ = "cannot read the summary of " + path;
    return;
  }
  Decoder in(summary);
  bool have_stats = false;
  while (in.remaining() > 0) {
    const auto op = static_cast<Opcode>(in.u8());
    const std::uint64_t length = in.u64();
    const auto body = in.bytes(length);
    if (!in.ok()) {
      error_ = "the summary of " + path + " is cut off";
      return;
    }
    bool ok = true;
    if (op == Opcode::kSchema) {
      auto s = decode_schema(body, ok);
      if (ok) schemas_[s.id] = std::move(s);
    } else if (op == Opcode::kChannel) {
      auto c = decode_channel(body, ok);
      if (ok) channels_[c.id] = std::move(c);
    } else if (op == Opcode::kChunkIndex) {
      auto c = decode_chunk_index(body, ok);
      if (ok) chunks_.push_back(std::move(c));
    } else if (op == Opcode::kStatistics) {
      const Statistics s = decode_statistics(body, ok);
      if (ok) {
        have_stats = true;
        start_time_ = s.message_start_time;
        end_time_ = s.message_end_time;
        message_count_ = s.message_count;
      }
    }
    if (!ok) {
      error_ = "a damaged record in the summary of " + path;
      return;
    }
  }
  if (chunks_.empty()) {
    error_ = path + " has no chunk index";
    return;
  }
  std::sort(chunks_.begin(), chunks_.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
    return a.message_start_time < b.message_start_time;
  });
  if (!have_stats) {
    start_time_ = chunks_.front().message_start_time;
    end_time_ = 0;
    for (const auto& c : chunks_) end_time_ = std::max(end_time_, c.message_end_time);
  }
}

IndexedReader::~IndexedReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool IndexedReader::pread_exact(std::uint64_t offset, std::uint64_t size,
                                std::vector<std::uint8_t>& out) {
  if (offset > size_ || size > size_ - offset) return false;
  out.resize(size);
  std::uint64_t done = 0;
  while (done < size) {
    const ssize_t n =
        ::pread(fd_, out.data() + done, size - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::uint64_t>(n);
  }
  return true;
}

bool IndexedReader::load_chunk(std::size_t index) {
  if (loaded_ == index) return true;
  loaded_.reset();
  const ChunkIndex& c = chunks_[index];
  if (c.chunk_length < 9 || c.chunk_length > kMaxChunkBytes) return false;
  if (!pread_exact(c.chunk_start_offset, c.chunk_length, raw_)) return false;
  if (raw_[0] != static_cast<std::uint8_t>(Opcode::kChunk)) return false;
  Decoder d(std::span<const std::uint8_t>(raw_).subspan(9));
  d.u64();
  d.u64();
  const std::uint64_t uncompressed_size = d.u64();
  const std::uint32_t crc = d.u32();
  const std::string compression = d.string();
  const std::uint64_t size = d.u64();
  const auto records = d.bytes(size);
  if (!d.ok() || uncompressed_size > kMaxChunkBytes) return false;
  if (!detail::decompress(compression, records, uncompressed_size, records_)) return false;
  if (crc != 0 && crc32(0, records_.data(), records_.size()) != crc) return false;
  ++chunks_read_;
  loaded_ = index;
  return true;
}

bool IndexedReader::scan_loaded_chunk(const std::function<void(const MessageView&)>& fn) const {
  Decoder in(records_);
  while (in.remaining() > 0) {
    const auto op = static_cast<Opcode>(in.u8());
    const std::uint64_t length = in.u64();
    const auto body = in.bytes(length);
    if (!in.ok()) return false;
    if (op != Opcode::kMessage) continue;
    bool ok = true;
    const MessageView m = decode_message(body, ok);
    if (!ok) return false;
    fn(m);
  }
  return true;
}

bool IndexedReader::read(std::uint64_t begin, std::uint64_t end, const Handler& fn) {
  if (!ok() || begin >= end) return ok();
  struct Found {
    std::uint64_t log_time;
    std::size_t order;
    const Channel* channel;
    MessageView view;
  };
  for (std::size_t i = 0; i < chunks_.size(); ++i) {
    const ChunkIndex& c = chunks_[i];
    if (c.message_end_time < begin || c.message_start_time >= end) continue;
    if (!load_chunk(i)) return false;
    // Messages of a chunk are in arrival order, nearly sorted by log time.
    std::vector<Found> found;
    const bool whole = scan_loaded_chunk([&](const MessageView& m) {
      if (m.log_time < begin || m.log_time >= end) return;
      auto ch = channels_.find(m.channel_id);
      if (ch == channels_.end()) return;
      found.push_back({m.log_time, found.size(), &ch->second, m});
    });
    if (!whole) return false;
    std::stable_sort(found.begin(), found.end(),
                     [](const Found& a, const Found& b) { return a.log_time < b.log_time; });
    for (const auto& f : found) fn(*f.channel, f.view);
  }
  return true;
}

bool IndexedReader::read_newest(std::uint64_t end, const ChannelFilter& wanted, const Handler& fn) {
  if (!ok()) return false;
  struct Newest {
    std::uint64_t log_time = 0;
    std::uint64_t publish_time = 0;
    std::uint32_t sequence = 0;
    std::vector<std::uint8_t> data;  // copied: the next chunk read replaces the buffer
  };
  std::map<std::uint16_t, Newest> newest;
  std::map<std::uint16_t, bool> wants;
  for (const auto& [id, channel] : channels_) wants[id] = wanted(channel);
  // From the last chunk back. A chunk is read only if it holds a wanted
  // channel whose newest message found so far is older than the chunk's
  // end: the index scan costs nothing, the reads stay few.
  for (std::size_t i = chunks_.size(); i-- > 0;) {
    const ChunkIndex& c = chunks_[i];
    if (c.message_start_time >= end) continue;
    bool useful = false;
    for (const auto& [id, offset] : c.message_index_offsets) {
      (void)offset;
      if (!wants[id]) continue;
      const auto found = newest.find(id);
      if (found == newest.end() || found->second.log_time < c.message_end_time) useful = true;
    }
    if (!useful) continue;
    if (!load_chunk(i)) return false;
    const bool whole = scan_loaded_chunk([&](const MessageView& m) {
      if (m.log_time >= end || !wants[m.channel_id]) return;
      auto [it, fresh] = newest.try_emplace(m.channel_id);
      if (!fresh && it->second.log_time > m.log_time) return;
      it->second.log_time = m.log_time;
      it->second.publish_time = m.publish_time;
      it->second.sequence = m.sequence;
      it->second.data.assign(m.data.begin(), m.data.end());
    });
    if (!whole) return false;
  }
  std::vector<std::pair<std::uint16_t, const Newest*>> order;
  for (const auto& [id, n] : newest) order.emplace_back(id, &n);
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return a.second->log_time < b.second->log_time;
  });
  for (const auto& [id, n] : order) {
    MessageView view;
    view.channel_id = id;
    view.sequence = n->sequence;
    view.log_time = n->log_time;
    view.publish_time = n->publish_time;
    view.data = n->data;
    fn(channels_.at(id), view);
  }
  return true;
}

}  // namespace fahr::mcap
