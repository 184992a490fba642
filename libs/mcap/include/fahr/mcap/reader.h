// A linear MCAP reader: walks every record from the leading magic, opens
// chunks (zstd, lz4, none) and checks every CRC it finds (chunk, data
// section, summary). Good for checks, `fahr_mcap info` and recovery; it
// does not use the index for random access.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fahr/mcap/records.h"

namespace fahr::mcap {

struct ReadReport {
  std::string profile, library;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<Metadata> metadata;
  std::optional<Statistics> statistics;  // the summary's
  std::vector<ChunkIndex> chunk_indexes;
  std::uint64_t messages = 0;
  std::map<std::uint16_t, std::uint64_t> channel_messages;
  std::map<std::uint16_t, std::uint64_t> channel_bytes;  // message data, uncompressed
  std::uint64_t message_start_time = 0, message_end_time = 0;
  std::uint64_t chunks = 0;
  std::set<std::string> compressions;
  std::uint64_t file_size = 0;
  // CRCs: how many were checked and how many failed; a zero CRC is counted
  // as absent.
  std::uint32_t crcs_checked = 0, crc_failures = 0, crcs_absent = 0;
  bool data_end = false;  // a Data End record was found
  bool footer = false;    // a Footer and the trailing magic were found
  // Byte offset just past the last complete, valid data-section record
  // (a chunk counts only with its CRC and decompression intact).
  std::uint64_t valid_data_end = 0;
  // Empty if the file is complete and valid; else why not.
  std::string error;
  bool valid() const { return error.empty() && footer && crc_failures == 0; }
};

using MessageHandler = std::function<void(const Channel& channel, const MessageView& message)>;

// Reads `path`; `on_message`, if set, sees every message in file order.
// Never throws on a malformed file: the report says what is wrong.
ReadReport read_file(const std::string& path, const MessageHandler& on_message = {});

struct RecoverResult {
  std::string output;  // the rebuilt file
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  std::uint64_t dropped_bytes = 0;  // the torn tail that was not kept
};

// Rebuilds a valid MCAP file from a torn one (a .part left by a killed
// recorder): every schema, channel, metadata record and complete chunk up to
// the first damaged record, written again with indexes and a summary.
// Output: `path` without ".part", or `output` if given. Throws
// std::runtime_error if nothing can be read.
RecoverResult recover(const std::string& path, const std::string& output = {});

}  // namespace fahr::mcap
