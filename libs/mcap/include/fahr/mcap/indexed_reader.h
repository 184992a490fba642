// A random-access MCAP reader for replays: it reads the footer and the
// summary section (schemas, channels, chunk indexes, statistics) and then
// only the chunks that cover a requested span of log time, one at a time,
// with pread. A recording of gigabytes costs the memory of one chunk.
// Files without a summary (a .part left by a killed recorder) are refused:
// `fahr_mcap recover` rebuilds them with one.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fahr/mcap/records.h"

namespace fahr::mcap {

class IndexedReader {
 public:
  // Opens `path` and reads its summary; error() says why it cannot be used.
  explicit IndexedReader(const std::string& path);
  ~IndexedReader();
  IndexedReader(const IndexedReader&) = delete;
  IndexedReader& operator=(const IndexedReader&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }
  // Chunk indexes, by message_start_time.
  const std::vector<ChunkIndex>& chunks() const { return chunks_; }
  std::uint64_t start_time() const { return start_time_; }  // log time, ns
  std::uint64_t end_time() const { return end_time_; }
  std::uint64_t message_count() const { return message_count_; }

  // Calls `fn` for every message with begin <= log_time < end, in log-time
  // order, reading only the chunks whose span overlaps [begin, end). False
  // if a chunk is damaged (its CRC or decompression fails).
  using Handler = std::function<void(const Channel&, const MessageView&)>;
  bool read(std::uint64_t begin, std::uint64_t end, const Handler& fn);

  // Calls `fn` for the newest message with log_time < end of each channel
  // that `wanted` accepts, however long before `end` it was written, in
  // log-time order: the state as it stood at `end`. Reads only chunks that
  // hold a wanted channel (the chunk indexes say which) and could hold a
  // newer message of it than one already found. False if a chunk is
  // damaged.
  using ChannelFilter = std::function<bool(const Channel&)>;
  bool read_newest(std::uint64_t end, const ChannelFilter& wanted, const Handler& fn);

  // Chunk reads so far (a test checks that a seek reads few).
  std::uint64_t chunks_read() const { return chunks_read_; }

 private:
  bool pread_exact(std::uint64_t offset, std::uint64_t size, std::vector<std::uint8_t>& out);
  bool load_chunk(std::size_t index);
  // Calls `fn` for each message of the loaded chunk; false if it is damaged.
  bool scan_loaded_chunk(const std::function<void(const MessageView&)>& fn) const;

  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::string error_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<ChunkIndex> chunks_;
  std::uint64_t start_time_ = 0, end_time_ = 0, message_count_ = 0;
  // The one chunk held: its index and uncompressed records.
  std::optional<std::size_t> loaded_;
  std::vector<std::uint8_t> raw_, records_;
  std::uint64_t chunks_read_ = 0;
};

}  // namespace fahr::mcap
