// fahr_mcap: what an MCAP recording holds, and repair of a torn one.
//
//   fahr_mcap info FILE       schemas, channels, counts, time span, metadata,
//                             CRCs; exit status 1 if the file is not valid
//   fahr_mcap recover FILE [-o OUT]
//                             rebuild a valid file from a torn one (a .part
//                             left by a killed recorder): every complete chunk
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <string>

#include "fahr/cli/cli.h"
#include "fahr/mcap/reader.h"

namespace {

std::string shorten(const std::string& text, std::size_t limit) {
  std::string one_line;
  for (char c : text) one_line += (c == '\n' || c == '\r') ? ' ' : c;
  if (one_line.size() <= limit) return one_line;
  return one_line.substr(0, limit) + "... (" + std::to_string(text.size()) + " bytes)";
}

int info(const std::string& path) {
  const auto r = fahr::mcap::read_file(path);
  std::printf("file:        %s (%llu bytes)\n", path.c_str(),
              static_cast<unsigned long long>(r.file_size));
  std::printf("library:     %s%s%s\n", r.library.c_str(), r.profile.empty() ? "" : ", profile ",
              r.profile.c_str());
  const double span_s = static_cast<double>(r.message_end_time - r.message_start_time) * 1e-9;
  std::printf("messages:    %llu in %llu chunks, %.3f s of log time\n",
              static_cast<unsigned long long>(r.messages),
              static_cast<unsigned long long>(r.chunks), span_s);
  std::string compressions;
  for (const auto& c : r.compressions) compressions += (c.empty() ? "none" : c) + " ";
  std::printf("compression: %s\n", compressions.empty() ? "-" : compressions.c_str());
  std::printf("crc:         %u checked, %u failed, %u absent\n", r.crcs_checked, r.crc_failures,
              r.crcs_absent);
  std::printf("summary:     %s\n", r.statistics ? "statistics, chunk indexes" : "none");
  std::printf("schemas:\n");
  for (const auto& [id, s] : r.schemas) {
    std::printf("  %3u %-32s %s, %zu bytes\n", id, s.name.c_str(), s.encoding.c_str(),
                s.data.size());
  }
  std::printf("channels:\n");
  for (const auto& [id, c] : r.channels) {
    const auto n = r.channel_messages.count(id) != 0 ? r.channel_messages.at(id) : 0;
    const auto bytes = r.channel_bytes.count(id) != 0 ? r.channel_bytes.at(id) : 0;
    std::string key;
    if (auto it = c.metadata.find("key"); it != c.metadata.end()) key = " [" + it->second + "]";
    std::printf("  %3u %-24s%-22s %8llu msgs %9.2f MiB  (%s)\n", id, c.topic.c_str(), key.c_str(),
                static_cast<unsigned long long>(n), static_cast<double>(bytes) / (1 << 20),
                c.message_encoding.c_str());
  }
  for (const auto& m : r.metadata) {
    std::printf("metadata %s:\n", m.name.c_str());
    for (const auto& [k, v] : m.values)
      std::printf("  %-24s %s\n", k.c_str(), shorten(v, 90).c_str());
  }
  if (!r.valid()) {
    std::printf("NOT VALID: %s%s\n", r.error.c_str(), r.crc_failures > 0 ? " (CRC mismatch)" : "");
    return 1;
  }
  std::printf("valid\n");
  return 0;
}

int recover(const std::string& path, const std::string& output) {
  const bool tty = isatty(STDERR_FILENO) != 0;
  if (tty) std::fprintf(stderr, "fahr_mcap: recovering %s ...\n", path.c_str());
  const auto result = fahr::mcap::recover(path, output);
  std::printf(
      "recovered %llu messages from %llu complete chunks into %s (%llu torn bytes left out)\n",
      static_cast<unsigned long long>(result.messages),
      static_cast<unsigned long long>(result.chunks), result.output.c_str(),
      static_cast<unsigned long long>(result.dropped_bytes));
  return 0;
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_mcap: inspect and repair MCAP recordings"};
  app.require_subcommand(1);
  std::string path, output;
  auto* info_cmd = app.add_subcommand("info", "what the file holds; exit 1 if not valid");
  info_cmd->add_option("file", path, "MCAP file")->required();
  auto* recover_cmd =
      app.add_subcommand("recover", "rebuild a valid file from a torn one (e.g. NAME.mcap.part)");
  recover_cmd->add_option("file", path, "torn MCAP file")->required();
  recover_cmd->add_option("-o,--output", output, "output (default: FILE without .part)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  if (info_cmd->parsed()) return info(path);
  return recover(path, output);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_mcap: %s\n", e.what());
    return 2;
  }
}
