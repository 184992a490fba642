// Linear MCAP reader with CRC checks.
#include "fahr/mcap/reader.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "compression.h"

namespace fahr::mcap {
namespace {

// The whole file, mapped read-only.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size > 0) {
      size_ = static_cast<std::size_t>(st.st_size);
      void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (p != MAP_FAILED) data_ = static_cast<const std::uint8_t*>(p);
    }
    opened_ = true;
    ::close(fd);
  }
  ~MappedFile() {
    if (data_ != nullptr) ::munmap(const_cast<std::uint8_t*>(data_), size_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  bool opened() const { return opened_; }
  std::span<const std::uint8_t> bytes() const {
    return data_ == nullptr ? std::span<const std::uint8_t>{} : std::span{data_, size_};
  }

 private:
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  bool opened_ = false;
};

void check_crc(ReadReport& r, std::uint32_t stored, std::uint32_t computed) {
  if (stored == 0) {
    ++r.crcs_absent;
    return;
  }
  ++r.crcs_checked;
  if (stored != computed) ++r.crc_failures;
}

// Opens one chunk and hands its messages on; false if it is damaged.
bool read_chunk(std::span<const std::uint8_t> content, ReadReport& r,
                const MessageHandler& on_message, std::vector<std::uint8_t>& buffer) {
  Decoder d(content);
  const std::uint64_t start_time = d.u64();
  const std::uint64_t end_time = d.u64();
  const std::uint64_t uncompressed_size = d.u64();
  const std::uint32_t crc = d.u32();
  const std::string compression = d.string();
  const std::uint64_t size = d.u64();
  const auto records = d.bytes(size);
  if (!d.ok()) return false;
  if (!detail::decompress(compression, records, uncompressed_size, buffer)) return false;
  if (crc != 0 && crc32(0, buffer.data(), buffer.size()) != crc) {
    ++r.crcs_checked;
    ++r.crc_failures;
    return false;
  }
  check_crc(r, crc, crc);
  (void)start_time;
  (void)end_time;
  r.compressions.insert(compression);
  Decoder in(buffer);
  while (in.remaining() > 0) {
    const auto op = static_cast<Opcode>(in.u8());
    const std::uint64_t length = in.u64();
    const auto body = in.bytes(length);
    if (!in.ok()) return false;
    bool ok = true;
    if (op == Opcode::kSchema) {
      auto s = decode_schema(body, ok);
      if (ok) r.schemas[s.id] = std::move(s);
    } else if (op == Opcode::kChannel) {
      auto c = decode_channel(body, ok);
      if (ok) r.channels[c.id] = std::move(c);
    } else if (op == Opcode::kMessage) {
      const MessageView m = decode_message(body, ok);
      if (!ok) return false;
      if (r.messages == 0) r.message_start_time = r.message_end_time = m.log_time;
      ++r.messages;
      ++r.channel_messages[m.channel_id];
      r.channel_bytes[m.channel_id] += m.data.size();
      r.message_start_time = std::min(r.message_start_time, m.log_time);
      r.message_end_time = std::max(r.message_end_time, m.log_time);
      if (on_message) {
        auto it = r.channels.find(m.channel_id);
        if (it == r.channels.end()) return false;  // a message before its channel
        on_message(it->second, m);
      }
    }
    if (!ok) return false;
  }
  ++r.chunks;
  return true;
}

}  // namespace

ReadReport read_file(const std::string& path, const MessageHandler& on_message) {
  ReadReport r;
  MappedFile file(path);
  if (!file.opened()) {
    r.error = "cannot open " + path;
    return r;
  }
  const auto all = file.bytes();
  r.file_size = all.size();
  if (all.size() < sizeof(kMagic) || std::memcmp(all.data(), kMagic, sizeof(kMagic)) != 0) {
    r.error = "no MCAP magic at the start";
    return r;
  }
  std::size_t pos = sizeof(kMagic);
  r.valid_data_end = pos;
  std::uint64_t summary_start = 0;
  std::vector<std::uint8_t> buffer;
  bool in_summary = false;
  while (true) {
    if (all.size() - pos < 9) {
      r.error = "truncated after byte " + std::to_string(pos) + " (no footer)";
      break;
    }
    const auto op = static_cast<Opcode>(all[pos]);
    std::uint64_t length = 0;
    for (int i = 0; i < 8; ++i) length |= static_cast<std::uint64_t>(all[pos + 1 + i]) << (8 * i);
    if (length > all.size() - pos - 9) {
      r.error = "record at byte " + std::to_string(pos) + " is cut off (no footer)";
      break;
    }
    const auto content = all.subspan(pos + 9, length);
    const std::size_t next = pos + 9 + length;
    bool ok = true;
    switch (op) {
      case Opcode::kHeader: {
        Decoder d(content);
        r.profile = d.string();
        r.library = d.string();
        ok = d.ok();
        break;
      }
      case Opcode::kSchema: {
        auto s = decode_schema(content, ok);
        if (ok) r.schemas[s.id] = std::move(s);
        break;
      }
      case Opcode::kChannel: {
        auto c = decode_channel(content, ok);
        if (ok) r.channels[c.id] = std::move(c);
        break;
      }
      case Opcode::kMetadata: {
        auto m = decode_metadata(content, ok);
        if (ok) r.metadata.push_back(std::move(m));
        break;
      }
      case Opcode::kChunk:
        ok = read_chunk(content, r, on_message, buffer);
        break;
      case Opcode::kStatistics:
        r.statistics = decode_statistics(content, ok);
        break;
      case Opcode::kChunkIndex:
        r.chunk_indexes.push_back(decode_chunk_index(content, ok));
        break;
      case Opcode::kDataEnd: {
        Decoder d(content);
        check_crc(r, d.u32(), crc32(0, all.data(), pos));
        r.data_end = true;
        in_summary = true;
        summary_start = next;
        break;
      }
      case Opcode::kFooter: {
        Decoder d(content);
        const std::uint64_t stored_start = d.u64();
        d.u64();
        const std::uint32_t crc = d.u32();
        if (stored_start != 0) {
          if (stored_start != summary_start) {
            r.error = "footer: summary_start does not match the Data End record";
          }
          check_crc(r, crc, crc32(0, all.data() + stored_start, pos + 9 + 16 - stored_start));
        }
        if (all.size() - next != sizeof(kMagic) ||
            std::memcmp(all.data() + next, kMagic, sizeof(kMagic)) != 0) {
          r.error = "no MCAP magic after the footer";
        } else {
          r.footer = true;
        }
        return r;
      }
      default:
        break;  // message indexes, summary offsets, unknown records
    }
    if (!ok) {
      r.error = "damaged record (opcode " + std::to_string(static_cast<int>(op)) + ") at byte " +
                std::to_string(pos);
      break;
    }
    pos = next;
    if (!in_summary) r.valid_data_end = pos;
  }
  return r;
}

}  // namespace fahr::mcap
