// An MCAP writer (specification: https://mcap.dev/spec). Messages go into
// chunks (about 1 MiB, zstd, lz4 or uncompressed), each followed by its
// message indexes; Schema, Channel and Metadata records go straight into
// the data section. close() writes Data End with the data section's CRC,
// the summary (schemas, channels, statistics, metadata and chunk indexes),
// summary offsets and the footer with the summary's CRC.
//
// The file is written as NAME.part and renamed to NAME on close, so a
// complete name is always a complete file. Every chunk is written with one
// flush (and fdatasync, unless turned off) when it is full or older than
// max_chunk_age_ns, so after a crash every chunk but the open one is on
// disk: fahr::mcap::recover() rebuilds a valid file from the .part.
//
// Not thread-safe: one thread owns a Writer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "fahr/mcap/records.h"

namespace fahr::mcap {

struct WriterOptions {
  std::string compression = "zstd";  // "zstd", "lz4" or "" (none)
  // zstd level (1 is the fastest regular level); lz4 frame level (0: fast).
  int compression_level = 1;
  std::uint64_t chunk_size = 1 << 20;
  // A chunk whose first message is older than this (in log time) is written
  // out on the next write_message() or poll().
  std::int64_t max_chunk_age_ns = 1'000'000'000;
  bool sync_chunks = true;  // fdatasync after each chunk
  std::string profile;      // the Header's profile ("" for none)
  std::string library = "fahr::mcap";
  // Start a new file past this size or this span of log time (0: never).
  // Files after the first are NAME_1.mcap, NAME_2.mcap, ...
  std::uint64_t split_bytes = 0;
  std::int64_t split_duration_ns = 0;
  // Appended to the name while the file is open.
  std::string part_suffix = ".part";
};

class Writer {
 public:
  explicit Writer(WriterOptions options = {});
  ~Writer();  // closes an open file
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Creates `path`.part. Throws std::runtime_error if it cannot.
  void open(const std::string& path);
  // `schema.id` / `channel.id` 0: the writer assigns the next free id (from 1).
  std::uint16_t add_schema(Schema schema);
  std::uint16_t add_channel(Channel channel);
  void write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                     std::uint64_t publish_time, const void* data, std::size_t size);
  void write_metadata(const Metadata& metadata);
  // Writes the open chunk out if it is older than max_chunk_age_ns at `now`
  // (log-time clock). For a writer thread that found nothing to write.
  void poll(std::uint64_t now);
  // Writes the open chunk out now.
  void flush();
  // Summary, footer, rename to the final name. Safe to call twice.
  void close();

  bool is_open() const { return fd_ >= 0; }
  // Final names of every file closed so far, and of the open one.
  const std::vector<std::string>& files() const { return files_; }
  std::uint64_t messages_written() const { return total_messages_; }
  std::uint64_t bytes_written() const { return total_bytes_ + offset_; }

 private:
  void open_file(const std::string& path);
  void close_file();
  void flush_chunk();
  void write_out(const void* data, std::size_t size);
  void write_pending();
  void maybe_split(std::uint64_t log_time);

  WriterOptions options_;
  std::string base_path_;
  std::vector<std::string> files_;
  int split_index_ = 0;
  int fd_ = -1;
  std::string part_path_;
  std::uint64_t offset_ = 0;           // bytes written to the file so far
  std::uint32_t data_crc_ = 0;         // CRC of every byte written so far
  std::vector<std::uint8_t> pending_;  // records not yet written (not in chunks)
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<Metadata> metadata_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> metadata_index_;  // offset, length
  std::vector<std::string> metadata_names_;
  std::uint16_t next_schema_id_ = 1;
  std::uint16_t next_channel_id_ = 1;
  // The open chunk.
  std::vector<std::uint8_t> chunk_;
  std::vector<std::uint8_t> compressed_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::uint64_t chunk_messages_ = 0;
  // Summary of the open file.
  std::vector<ChunkIndex> chunk_indexes_;
  Statistics stats_;
  std::uint64_t file_start_time_ = 0;
  std::uint64_t total_messages_ = 0;
  std::uint64_t total_bytes_ = 0;  // of closed files
};

// Final name of split file `index` (0: `path` itself).
std::string split_file_name(const std::string& path, int index);

}  // namespace fahr::mcap
