// MCAP writer: chunks with message indexes, summary with CRCs, .part rename.
#include "fahr/mcap/writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "compression.h"

namespace fahr::mcap {

std::string split_file_name(const std::string& path, int index) {
  if (index == 0) return path;
  const std::string suffix = ".mcap";
  std::string stem = path;
  if (stem.size() > suffix.size() &&
      stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
    stem.resize(stem.size() - suffix.size());
  }
  return stem + "_" + std::to_string(index) + suffix;
}

Writer::Writer(WriterOptions options) : options_(std::move(options)) {
  if (!options_.compression.empty() && options_.compression != "zstd" &&
      options_.compression != "lz4") {
    throw std::invalid_argument("MCAP compression must be zstd, lz4 or none, not '" +
                                options_.compression + "'");
  }
}

Writer::~Writer() {
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr::mcap: closing %s failed: %s\n", part_path_.c_str(), e.what());
  }
}

void Writer::open(const std::string& path) {
  close();
  base_path_ = path;
  split_index_ = 0;
  files_.clear();
  total_bytes_ = 0;
  total_messages_ = 0;
  open_file(path);
}

void Writer::open_file(const std::string& path) {
  part_path_ = path + options_.part_suffix;
  fd_ = ::open(part_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error("cannot create " + part_path_ + ": " + std::strerror(errno));
  }
  files_.push_back(path);
  offset_ = 0;
  data_crc_ = 0;
  pending_.clear();
  chunk_indexes_.clear();
  metadata_index_.clear();
  metadata_names_.clear();
  stats_ = Statistics{};
  file_start_time_ = 0;
  Encoder e(pending_);
  e.bytes(kMagic, sizeof(kMagic));
  const auto start = e.begin_record(Opcode::kHeader);
  e.string(options_.profile);
  e.string(options_.library);
  e.finish_record(start);
  // A split file repeats every definition, so it stands alone.
  for (const auto& [id, schema] : schemas_) encode_schema(e, schema);
  for (const auto& [id, channel] : channels_) encode_channel(e, channel);
  for (const auto& m : metadata_) {
    const std::uint64_t at = offset_ + pending_.size();
    encode_metadata(e, m);
    metadata_index_.emplace_back(at, offset_ + pending_.size() - at);
    metadata_names_.push_back(m.name);
  }
  write_pending();
}

std::uint16_t Writer::add_schema(Schema schema) {
  if (schema.id == 0) schema.id = next_schema_id_;
  next_schema_id_ = std::max<std::uint16_t>(next_schema_id_, schema.id + 1);
  if (is_open()) {
    Encoder e(pending_);
    encode_schema(e, schema);
  }
  const std::uint16_t id = schema.id;
  schemas_[id] = std::move(schema);
  return id;
}

std::uint16_t Writer::add_channel(Channel channel) {
  if (channel.id == 0) channel.id = next_channel_id_;
  next_channel_id_ = std::max<std::uint16_t>(next_channel_id_, channel.id + 1);
  if (is_open()) {
    Encoder e(pending_);
    encode_channel(e, channel);
  }
  const std::uint16_t id = channel.id;
  channels_[id] = std::move(channel);
  return id;
}

void Writer::write_metadata(const Metadata& metadata) {
  metadata_.push_back(metadata);
  if (!is_open()) return;
  Encoder e(pending_);
  const std::uint64_t at = offset_ + pending_.size();
  encode_metadata(e, metadata);
  metadata_index_.emplace_back(at, offset_ + pending_.size() - at);
  metadata_names_.push_back(metadata.name);
}

void Writer::write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                           std::uint64_t publish_time, const void* data, std::size_t size) {
  if (!is_open()) throw std::logic_error("fahr::mcap::Writer: write_message on a closed writer");
  maybe_split(log_time);
  if (chunk_messages_ == 0) {
    chunk_start_time_ = log_time;
    chunk_end_time_ = log_time;
  }
  chunk_start_time_ = std::min(chunk_start_time_, log_time);
  chunk_end_time_ = std::max(chunk_end_time_, log_time);
  chunk_index_[channel_id].emplace_back(log_time, chunk_.size());
  Encoder e(chunk_);
  e.u8(static_cast<std::uint8_t>(Opcode::kMessage));
  e.u64(2 + 4 + 8 + 8 + size);
  e.u16(channel_id);
  e.u32(sequence);
  e.u64(log_time);
  e.u64(publish_time);
  e.bytes(data, size);
  ++chunk_messages_;
  ++total_messages_;
  if (stats_.message_count == 0) {
    stats_.message_start_time = log_time;
    stats_.message_end_time = log_time;
    file_start_time_ = log_time;
  }
  ++stats_.message_count;
  ++stats_.channel_message_counts[channel_id];
  stats_.message_start_time = std::min(stats_.message_start_time, log_time);
  stats_.message_end_time = std::max(stats_.message_end_time, log_time);
  if (chunk_.size() >= options_.chunk_size ||
      static_cast<std::int64_t>(log_time - chunk_start_time_) > options_.max_chunk_age_ns) {
    flush_chunk();
  }
}

void Writer::poll(std::uint64_t now) {
  if (!is_open()) return;
  if (chunk_messages_ > 0 && now > chunk_start_time_ &&
      static_cast<std::int64_t>(now - chunk_start_time_) > options_.max_chunk_age_ns) {
    flush_chunk();
  } else if (!pending_.empty()) {
    write_pending();
  }
}

void Writer::flush() {
  if (is_open()) flush_chunk();
}

void Writer::maybe_split(std::uint64_t log_time) {
  const bool by_size = options_.split_bytes > 0 && offset_ + chunk_.size() >= options_.split_bytes;
  const bool by_time =
      options_.split_duration_ns > 0 && stats_.message_count > 0 &&
      static_cast<std::int64_t>(log_time - file_start_time_) >= options_.split_duration_ns;
  if (!by_size && !by_time) return;
  close_file();
  ++split_index_;
  open_file(split_file_name(base_path_, split_index_));
}

void Writer::write_out(const void* data, std::size_t size) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  data_crc_ = crc32(data_crc_, p, size);
  offset_ += size;
  while (size > 0) {
    const ssize_t n = ::write(fd_, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("writing " + part_path_ + ": " + std::strerror(errno));
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
}

void Writer::write_pending() {
  if (pending_.empty()) return;
  write_out(pending_.data(), pending_.size());
  pending_.clear();
}

void Writer::flush_chunk() {
  if (chunk_messages_ == 0) {
    write_pending();
    return;
  }
  write_pending();
  const std::uint32_t uncompressed_crc = crc32(0, chunk_.data(), chunk_.size());
  const std::uint8_t* body = chunk_.data();
  std::size_t body_size = chunk_.size();
  if (!options_.compression.empty()) {
    if (!detail::compress(options_.compression, chunk_, compressed_, options_.compression_level)) {
      throw std::runtime_error("compressing a chunk with " + options_.compression + " failed");
    }
    body = compressed_.data();
    body_size = compressed_.size();
  }
  ChunkIndex index;
  index.message_start_time = chunk_start_time_;
  index.message_end_time = chunk_end_time_;
  index.chunk_start_offset = offset_;
  index.compression = options_.compression;
  index.compressed_size = body_size;
  index.uncompressed_size = chunk_.size();

  Encoder e(pending_);
  const std::uint64_t content = 8 + 8 + 8 + 4 + 4 + options_.compression.size() + 8 + body_size;
  e.u8(static_cast<std::uint8_t>(Opcode::kChunk));
  e.u64(content);
  e.u64(chunk_start_time_);
  e.u64(chunk_end_time_);
  e.u64(chunk_.size());
  e.u32(uncompressed_crc);
  e.string(options_.compression);
  e.u64(body_size);
  write_pending();
  write_out(body, body_size);
  index.chunk_length = offset_ - index.chunk_start_offset;

  const std::uint64_t indexes_start = offset_;
  for (auto& [channel_id, entries] : chunk_index_) {
    if (entries.empty()) continue;
    std::stable_sort(entries.begin(), entries.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    index.message_index_offsets[channel_id] = offset_ + pending_.size();
    const auto start = e.begin_record(Opcode::kMessageIndex);
    e.u16(channel_id);
    e.u32(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      e.u64(time);
      e.u64(at);
    }
    e.finish_record(start);
    entries.clear();
  }
  write_pending();
  index.message_index_length = offset_ - indexes_start;
  chunk_indexes_.push_back(std::move(index));
  ++stats_.chunk_count;
  if (options_.sync_chunks) ::fdatasync(fd_);
  chunk_.clear();
  chunk_messages_ = 0;
}

void Writer::close() {
  if (fd_ < 0) return;
  close_file();
}

void Writer::close_file() {
  flush_chunk();
  write_pending();
  // Data End: the CRC of every byte before it.
  Encoder e(pending_);
  {
    const auto start = e.begin_record(Opcode::kDataEnd);
    e.u32(data_crc_);
    e.finish_record(start);
  }
  write_pending();

  // Summary, grouped by opcode; one Summary Offset per group.
  const std::uint64_t summary_start = offset_;
  data_crc_ = 0;  // from here on: the summary CRC
  struct Group {
    Opcode op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](Opcode op, auto&& body) {
    const std::uint64_t start = offset_ + pending_.size();
    body();
    const std::uint64_t end = offset_ + pending_.size();
    if (end > start) groups.push_back({op, start, end - start});
  };
  group(Opcode::kSchema, [&] {
    for (const auto& [id, s] : schemas_) encode_schema(e, s);
  });
  group(Opcode::kChannel, [&] {
    for (const auto& [id, c] : channels_) encode_channel(e, c);
  });
  group(Opcode::kStatistics, [&] {
    stats_.schema_count = static_cast<std::uint16_t>(schemas_.size());
    stats_.channel_count = static_cast<std::uint32_t>(channels_.size());
    stats_.metadata_count = static_cast<std::uint32_t>(metadata_index_.size());
    const auto start = e.begin_record(Opcode::kStatistics);
    e.u64(stats_.message_count);
    e.u16(stats_.schema_count);
    e.u32(stats_.channel_count);
    e.u32(stats_.attachment_count);
    e.u32(stats_.metadata_count);
    e.u32(stats_.chunk_count);
    e.u64(stats_.message_start_time);
    e.u64(stats_.message_end_time);
    e.u32(static_cast<std::uint32_t>(stats_.channel_message_counts.size() * 10));
    for (const auto& [id, n] : stats_.channel_message_counts) {
      e.u16(id);
      e.u64(n);
    }
    e.finish_record(start);
  });
  group(Opcode::kMetadataIndex, [&] {
    for (std::size_t i = 0; i < metadata_index_.size(); ++i) {
      const auto start = e.begin_record(Opcode::kMetadataIndex);
      e.u64(metadata_index_[i].first);
      e.u64(metadata_index_[i].second);
      e.string(metadata_names_[i]);
      e.finish_record(start);
    }
  });
  group(Opcode::kChunkIndex, [&] {
    for (const auto& c : chunk_indexes_) {
      const auto start = e.begin_record(Opcode::kChunkIndex);
      e.u64(c.message_start_time);
      e.u64(c.message_end_time);
      e.u64(c.chunk_start_offset);
      e.u64(c.chunk_length);
      e.u32(static_cast<std::uint32_t>(c.message_index_offsets.size() * 10));
      for (const auto& [id, at] : c.message_index_offsets) {
        e.u16(id);
        e.u64(at);
      }
      e.u64(c.message_index_length);
      e.string(c.compression);
      e.u64(c.compressed_size);
      e.u64(c.uncompressed_size);
      e.finish_record(start);
    }
  });
  const std::uint64_t summary_offset_start = offset_ + pending_.size();
  for (const auto& g : groups) {
    const auto start = e.begin_record(Opcode::kSummaryOffset);
    e.u8(static_cast<std::uint8_t>(g.op));
    e.u64(g.start);
    e.u64(g.length);
    e.finish_record(start);
  }
  // Footer: the summary CRC covers the summary up to and including
  // summary_offset_start.
  e.u8(static_cast<std::uint8_t>(Opcode::kFooter));
  e.u64(8 + 8 + 4);
  e.u64(summary_start);
  e.u64(summary_offset_start);
  write_pending();
  const std::uint32_t summary_crc = data_crc_;
  e.u32(summary_crc);
  e.bytes(kMagic, sizeof(kMagic));
  write_pending();

  ::fsync(fd_);
  ::close(fd_);
  fd_ = -1;
  total_bytes_ += offset_;
  offset_ = 0;
  if (std::rename(part_path_.c_str(), files_.back().c_str()) != 0) {
    throw std::runtime_error("cannot rename " + part_path_ + ": " + std::strerror(errno));
  }
}

}  // namespace fahr::mcap
