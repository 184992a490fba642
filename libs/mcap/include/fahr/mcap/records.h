// The MCAP records fahr writes and reads, as plain values, and the
// little-endian primitives of the format (MCAP specification, "Records" and
// "Serialization"). Opcodes and field orders follow the specification.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace fahr::mcap {

// 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n': the first and last 8 bytes of a file.
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

using KeyValues = std::map<std::string, std::string>;

struct Schema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::string data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  KeyValues metadata;
};

// A message as the reader hands it out: `data` points into the reader's
// buffer and is valid during the callback only.
struct MessageView {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::span<const std::uint8_t> data;
};

struct Metadata {
  std::string name;
  KeyValues values;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

struct ChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

// CRC-32 (ISO-HDLC, the zlib polynomial), continued from `crc`.
std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size);

// Appends MCAP primitives to a byte buffer.
class Encoder {
 public:
  explicit Encoder(std::vector<std::uint8_t>& out) : out_(out) {}
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void string(std::string_view s);
  void bytes(const void* data, std::size_t size);
  void key_values(const KeyValues& map);
  // Starts a record; finish_record() fills in its length.
  std::size_t begin_record(Opcode op);
  void finish_record(std::size_t start);

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t>& out_;
};

// Reads MCAP primitives from a byte range; every read checks the bounds and
// sets ok() false instead of reading past the end.
class Decoder {
 public:
  explicit Decoder(std::span<const std::uint8_t> in) : in_(in) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::uint64_t u64() { return le(8); }
  std::string string();
  std::span<const std::uint8_t> bytes(std::uint64_t size);
  KeyValues key_values();
  std::map<std::uint16_t, std::uint64_t> u16_u64_map();
  bool ok() const { return ok_; }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return in_.size() - pos_; }

 private:
  std::uint64_t le(int n);
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// Record encoders shared by the writer and the recovery.
void encode_schema(Encoder& e, const Schema& s);
void encode_channel(Encoder& e, const Channel& c);
void encode_metadata(Encoder& e, const Metadata& m);

// Record decoders: the content of a record (after opcode and length).
Schema decode_schema(std::span<const std::uint8_t> content, bool& ok);
Channel decode_channel(std::span<const std::uint8_t> content, bool& ok);
Metadata decode_metadata(std::span<const std::uint8_t> content, bool& ok);
MessageView decode_message(std::span<const std::uint8_t> content, bool& ok);
Statistics decode_statistics(std::span<const std::uint8_t> content, bool& ok);
ChunkIndex decode_chunk_index(std::span<const std::uint8_t> content, bool& ok);

}  // namespace fahr::mcap
