// Recovery of a torn recording: read what is intact, write it again.
#include <stdexcept>

#include "fahr/mcap/reader.h"
#include "fahr/mcap/writer.h"

namespace fahr::mcap {

RecoverResult recover(const std::string& path, const std::string& output) {
  RecoverResult result;
  result.output = output;
  if (result.output.empty()) {
    const std::string part = ".part";
    if (path.size() > part.size() &&
        path.compare(path.size() - part.size(), part.size(), part) == 0) {
      result.output = path.substr(0, path.size() - part.size());
    } else {
      result.output = path + ".recovered.mcap";
    }
  }
  // First pass: what is intact, and which compression the chunks used.
  const ReadReport scan = read_file(path);
  if (scan.valid_data_end <= sizeof(kMagic) && scan.schemas.empty()) {
    throw std::runtime_error(path + ": nothing recoverable (" + scan.error + ")");
  }
  WriterOptions options;
  options.compression = scan.compressions.empty() ? "zstd" : *scan.compressions.begin();
  options.sync_chunks = false;
  options.max_chunk_age_ns = INT64_MAX;
  options.library = scan.library.empty() ? "fahr::mcap recover" : scan.library;
  options.profile = scan.profile;
  options.part_suffix = ".recovering";  // the input may well be OUTPUT.part
  Writer writer(options);
  writer.open(result.output);
  for (const auto& [id, schema] : scan.schemas) writer.add_schema(schema);
  for (const auto& [id, channel] : scan.channels) writer.add_channel(channel);
  for (const auto& m : scan.metadata) writer.write_metadata(m);
  // Second pass: the messages of every intact chunk, in file order.
  read_file(path, [&](const Channel& channel, const MessageView& m) {
    writer.write_message(channel.id, m.sequence, m.log_time, m.publish_time, m.data.data(),
                         m.data.size());
    ++result.messages;
  });
  writer.close();
  result.chunks = scan.chunks;
  result.dropped_bytes = scan.file_size - scan.valid_data_end;
  return result;
}

}  // namespace fahr::mcap
