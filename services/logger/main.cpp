// fahr_logger: the recorder participant. Subscribes to every fahr topic on
// either vendor and writes the samples, as they arrived, to an MCAP file
// (recorder.h); on SIGINT/SIGTERM or after --duration-s it closes the file
// with a valid summary and prints, per writer, what was sent, recorded,
// lost in transport (gaps) and dropped by the recorder.
//
//   fahr_logger -o FILE.mcap [--dds V] [--domain N] [--dds-profile F]
//               [--duration-s S] [--compression zstd|lz4|none] [--chunk-kib N]
//               [--split-mib N] [--split-s S] [--queue-mib N] [--no-fsync]
//               [--decimate TOPIC=N]... [--scene FILE]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <exception>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/stop_signal.h"
#include "fahr/logger_service/recorder.h"
#include "fahr/logger_service/run_metadata.h"

namespace fahr::logger_service {
namespace {

std::string default_name() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char text[64];
  std::strftime(text, sizeof(text), "fahr_%Y%m%d_%H%M%S.mcap", &tm);
  return text;
}

void print_table(const Recorder& recorder) {
  std::printf("fahr_logger: %-24s %10s %10s %10s %10s %8s %8s %8s\n", "topic", "writer", "sent",
              "recorded", "gaps", "(before)", "drops", "skipped");
  for (const auto& t : recorder.tallies()) {
    std::printf("fahr_logger: %-24s %10u %10llu %10llu %10llu %8llu %8llu %8llu\n", t.topic.c_str(),
                t.writer_id, static_cast<unsigned long long>(t.sent()),
                static_cast<unsigned long long>(t.recorded),
                static_cast<unsigned long long>(t.total_gaps()),
                static_cast<unsigned long long>(t.leading_gaps()),
                static_cast<unsigned long long>(t.drops),
                static_cast<unsigned long long>(t.skipped));
  }
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_logger: record every fahr topic to MCAP"};
  RecorderOptions options;
  options.path = default_name();
  std::string dds, domain, profile, scene, compression = "zstd";
  double duration_s = 0;
  std::uint64_t chunk_kib = 1024, split_mib = 1024, queue_mib = 256;
  double split_s = 0;
  bool no_fsync = false;
  std::vector<std::string> decimate;
  long writer_delay_us = 0;
  int writer_nice = 10;
  bool lockstep = false;
  app.add_option("-o,--out", options.path, "the recording (default fahr_<date>_<time>.mcap)");
  app.add_option("--dds", dds,
                 "DDS vendor: fastdds or cyclonedds (default $FAHR_DDS, else fastdds)");
  app.add_option("--domain", domain, "DDS domain 0-230 (default $FAHR_DOMAIN_ID, else 0)");
  app.add_option("--dds-profile", profile, "vendor XML profile (default $FAHR_DDS_PROFILE)");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  app.add_option("--duration-s", duration_s, "stop after this long (0: at SIGINT/SIGTERM)");
  app.add_option("--compression", compression, "chunk compression")
      ->check(fahr::cli::IsMember({"zstd", "lz4", "none"}));
  app.add_option("--chunk-kib", chunk_kib, "chunk size, KiB")->check(fahr::cli::Range(1, 1 << 20));
  app.add_option("--split-mib", split_mib, "start a new file past this size, MiB (0: never)");
  app.add_option("--split-s", split_s, "start a new file after this long, s (0: never)");
  app.add_option("--queue-mib", queue_mib,
                 "queue to the writer thread, MiB; beyond it samples "
                 "are dropped and counted")
      ->check(fahr::cli::Range(1, 1 << 16));
  app.add_flag("--no-fsync", no_fsync,
               "do not fdatasync each chunk (faster; a power loss may "
               "lose more than the open chunk)");
  app.add_option("--decimate", decimate,
                 "TOPIC=N: keep one sample in N of a topic (e.g. "
                 "fahr/DeformationState=10); the rest count as skipped");
  app.add_option("--writer-nice", writer_nice,
                 "nice value of the writer thread (compression, disk): >0 yields to the services")
      ->check(fahr::cli::Range(-20, 19));
  app.add_flag("--lockstep", lockstep,
               "a lockstep run: read the streams reliably (the services write them reliable and "
               "transient local)");
  app.add_option("--scene", scene, "scene file: its text goes into the recording's metadata");
  app.add_option("--writer-delay-us", writer_delay_us,
                 "testing: the writer thread sleeps this long per message (forces queue drops)");
  if (const auto exit = app.parse(argc, argv)) return *exit;

  options.mcap.compression = compression == "none" ? "" : compression;
  options.mcap.chunk_size = chunk_kib * 1024;
  options.mcap.split_bytes = split_mib * 1024 * 1024;
  options.mcap.split_duration_ns = static_cast<std::int64_t>(split_s * 1e9);
  options.mcap.sync_chunks = !no_fsync;
  options.mcap.library = "fahr_logger " FAHR_VERSION;
  options.queue_bytes = static_cast<std::size_t>(queue_mib) << 20;
  options.writer_delay = std::chrono::microseconds(writer_delay_us);
  options.writer_nice = writer_nice;
  options.lockstep = lockstep;
  for (const auto& d : decimate) {
    const auto eq = d.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "fahr_logger: --decimate wants TOPIC=N, not '%s'\n", d.c_str());
      return 2;
    }
    options.decimate[d.substr(0, eq)] = static_cast<std::uint32_t>(std::stoul(d.substr(eq + 1)));
  }

  common::install_stop_handlers();
  common::Participant participant(
      common::transport_config_from(dds, domain, profile, "logger", security));
  options.run_metadata = run_metadata(participant, scene);
  Recorder recorder(participant, options);
  std::printf("fahr_logger: recording to %s (%s, %s bytes, %s chunks of %llu KiB)\n",
              options.path.c_str(), std::string(common::vendor_name(participant.vendor())).c_str(),
              recorder.bytes_as_received() ? "CDR as received" : "re-serialised CDR",
              compression.c_str(), static_cast<unsigned long long>(chunk_kib));
  std::fflush(stdout);

  // Progress on a terminal, once a second; quiet otherwise. The writers
  // matched on the four streams, a line whenever they change: a lockstep
  // run starts its clock once the recorder has every writer
  // (deployment/run_local.sh), since a writer's history keeps only its last
  // few steps for a reader that matches late.
  const bool tty = isatty(STDERR_FILENO) != 0;
  const std::int64_t start = common::monotonic_now_ns();
  std::int64_t next_progress = start + 1'000'000'000;
  std::vector<std::pair<std::string, int>> said;
  while (!common::stop_requested()) {
    auto matched = recorder.matched_by_topic();
    matched.resize(std::min<std::size_t>(matched.size(), 4));  // the four streams
    if (matched != said) {
      std::printf("fahr_logger: writers matched:");
      for (std::size_t i = 0; i < matched.size(); ++i)
        std::printf("%s%s %d", i ? ", " : " ", matched[i].first.c_str(), matched[i].second);
      std::printf("\n");
      std::fflush(stdout);
      said = std::move(matched);
    }
    const std::int64_t now = common::monotonic_now_ns();
    const double elapsed_s = static_cast<double>(now - start) * 1e-9;
    if (duration_s > 0 && elapsed_s >= duration_s) break;
    if (tty && now >= next_progress) {
      const auto s = recorder.stats();
      std::fprintf(stderr, "\rfahr_logger: %.0f s%s%s, %llu samples, %llu dropped   ", elapsed_s,
                   duration_s > 0 ? " of " : "",
                   duration_s > 0 ? std::to_string(static_cast<int>(duration_s)).c_str() : "",
                   static_cast<unsigned long long>(s.written),
                   static_cast<unsigned long long>(s.dropped));
      next_progress += 1'000'000'000;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (tty) std::fprintf(stderr, "\n");
  recorder.stop();
  const auto s = recorder.stats();
  print_table(recorder);
  std::printf(
      "fahr_logger: %llu samples received, %llu written, %llu dropped (queue peak %.1f MiB), "
      "%llu skipped\n",
      static_cast<unsigned long long>(s.received), static_cast<unsigned long long>(s.written),
      static_cast<unsigned long long>(s.dropped),
      static_cast<double>(s.queue_peak_bytes) / (1 << 20),
      static_cast<unsigned long long>(s.skipped));
  for (const auto& f : recorder.files()) std::printf("fahr_logger: recorded %s\n", f.c_str());
  return 0;
}

}  // namespace
}  // namespace fahr::logger_service

int main(int argc, char** argv) {
  try {
    return fahr::logger_service::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_logger: %s\n", e.what());
    return 1;
  }
}
