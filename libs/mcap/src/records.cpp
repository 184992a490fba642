// MCAP primitives and the records shared by writer, reader and recovery.
#include "fahr/mcap/records.h"

#include <zlib.h>

#include <cstring>

namespace fahr::mcap {

std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size) {
  const auto* p = static_cast<const Bytef*>(data);
  // zlib takes uInt lengths: feed very large ranges in pieces.
  constexpr std::size_t kPiece = 1U << 30;
  while (size > 0) {
    const std::size_t n = size < kPiece ? size : kPiece;
    crc = static_cast<std::uint32_t>(::crc32(crc, p, static_cast<uInt>(n)));
    p += n;
    size -= n;
  }
  return crc;
}

void Encoder::string(std::string_view s) {
  u32(static_cast<std::uint32_t>(s.size()));
  bytes(s.data(), s.size());
}

void Encoder::bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  out_.insert(out_.end(), p, p + size);
}

void Encoder::key_values(const KeyValues& map) {
  std::uint32_t length = 0;
  for (const auto& [k, v] : map) length += static_cast<std::uint32_t>(8 + k.size() + v.size());
  u32(length);
  for (const auto& [k, v] : map) {
    string(k);
    string(v);
  }
}

std::size_t Encoder::begin_record(Opcode op) {
  const std::size_t start = out_.size();
  u8(static_cast<std::uint8_t>(op));
  u64(0);
  return start;
}

void Encoder::finish_record(std::size_t start) {
  const std::uint64_t length = out_.size() - start - 9;
  for (int i = 0; i < 8; ++i) out_[start + 1 + i] = static_cast<std::uint8_t>(length >> (8 * i));
}

std::uint64_t Decoder::le(int n) {
  if (!ok_ || remaining() < static_cast<std::size_t>(n)) {
    ok_ = false;
    return 0;
  }
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(in_[pos_ + i]) << (8 * i);
  pos_ += static_cast<std::size_t>(n);
  return v;
}

std::span<const std::uint8_t> Decoder::bytes(std::uint64_t size) {
  if (!ok_ || remaining() < size) {
    ok_ = false;
    return {};
  }
  auto out = in_.subspan(pos_, size);
  pos_ += size;
  return out;
}

std::string Decoder::string() {
  const std::uint32_t n = u32();
  auto b = bytes(n);
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

KeyValues Decoder::key_values() {
  KeyValues map;
  const std::uint32_t length = u32();
  const std::size_t end = pos_ + length;
  if (!ok_ || remaining() < length) {
    ok_ = false;
    return map;
  }
  while (ok_ && pos_ < end) {
    std::string k = string();
    std::string v = string();
    map.emplace(std::move(k), std::move(v));
  }
  if (pos_ != end) ok_ = false;
  return map;
}

std::map<std::uint16_t, std::uint64_t> Decoder::u16_u64_map() {
  std::map<std::uint16_t, std::uint64_t> map;
  const std::uint32_t length = u32();
  if (!ok_ || remaining() < length || length % 10 != 0) {
    ok_ = false;
    return map;
  }
  for (std::uint32_t i = 0; i < length / 10; ++i) {
    const std::uint16_t k = u16();
    map[k] = u64();
  }
  return map;
}

void encode_schema(Encoder& e, const Schema& s) {
  const auto start = e.begin_record(Opcode::kSchema);
  e.u16(s.id);
  e.string(s.name);
  e.string(s.encoding);
  e.u32(static_cast<std::uint32_t>(s.data.size()));
  e.bytes(s.data.data(), s.data.size());
  e.finish_record(start);
}

void encode_channel(Encoder& e, const Channel& c) {
  const auto start = e.begin_record(Opcode::kChannel);
  e.u16(c.id);
  e.u16(c.schema_id);
  e.string(c.topic);
  e.string(c.message_encoding);
  e.key_values(c.metadata);
  e.finish_record(start);
}

void encode_metadata(Encoder& e, const Metadata& m) {
  const auto start = e.begin_record(Opcode::kMetadata);
  e.string(m.name);
  e.key_values(m.values);
  e.finish_record(start);
}

Schema decode_schema(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  Schema s;
  s.id = d.u16();
  s.name = d.string();
  s.encoding = d.string();
  const std::uint32_t n = d.u32();
  auto data = d.bytes(n);
  s.data.assign(reinterpret_cast<const char*>(data.data()), data.size());
  ok = d.ok() && s.id != 0;
  return s;
}

Channel decode_channel(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  Channel c;
  c.id = d.u16();
  c.schema_id = d.u16();
  c.topic = d.string();
  c.message_encoding = d.string();
  c.metadata = d.key_values();
  ok = d.ok();
  return c;
}

Metadata decode_metadata(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  Metadata m;
  m.name = d.string();
  m.values = d.key_values();
  ok = d.ok();
  return m;
}

MessageView decode_message(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  MessageView m;
  m.channel_id = d.u16();
  m.sequence = d.u32();
  m.log_time = d.u64();
  m.publish_time = d.u64();
  m.data = d.bytes(d.remaining());
  ok = d.ok();
  return m;
}

Statistics decode_statistics(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  Statistics s;
  s.message_count = d.u64();
  s.schema_count = d.u16();
  s.channel_count = d.u32();
  s.attachment_count = d.u32();
  s.metadata_count = d.u32();
  s.chunk_count = d.u32();
  s.message_start_time = d.u64();
  s.message_end_time = d.u64();
  s.channel_message_counts = d.u16_u64_map();
  ok = d.ok();
  return s;
}

ChunkIndex decode_chunk_index(std::span<const std::uint8_t> content, bool& ok) {
  Decoder d(content);
  ChunkIndex c;
  c.message_start_time = d.u64();
  c.message_end_time = d.u64();
  c.chunk_start_offset = d.u64();
  c.chunk_length = d.u64();
  c.message_index_offsets = d.u16_u64_map();
  c.message_index_length = d.u64();
  c.compression = d.string();
  c.compressed_size = d.u64();
  c.uncompressed_size = d.u64();
  ok = d.ok();
  return c;
}

}  // namespace fahr::mcap
