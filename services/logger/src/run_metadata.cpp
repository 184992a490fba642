// The run's key/values: versions, host, time, scene text, chrony's offset.
#include "fahr/logger_service/run_metadata.h"

#include <dds/version.h>
#include <fastcdr/config.h>
#include <fastrtps/config.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>

#include "fahr/common/clock.h"
#include "fahr/common/vendor.h"

namespace fahr::logger_service {
namespace {

std::string host_name() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

// chrony's view of this host's clock (`chronyc -c tracking`: system time
// offset, s, is the fifth field), or why there is none.
std::string chrony_offset() {
  FILE* pipe = popen("chronyc -c tracking 2>/dev/null", "r");
  if (pipe == nullptr) return "unknown (chronyc could not run)";
  char line[512] = {};
  const bool got = std::fgets(line, sizeof(line), pipe) != nullptr;
  const int status = pclose(pipe);
  if (!got || status != 0) return "unknown (chronyc not installed or chronyd not running)";
  std::stringstream csv(line);
  std::string field;
  for (int i = 0; i < 5 && std::getline(csv, field, ','); ++i) {
  }
  return field + " s (chronyc tracking: system time offset)";
}

}  // namespace

std::map<std::string, std::string> run_metadata(const common::Participant& participant,
                                                const std::string& scene_path) {
  std::map<std::string, std::string> m;
  m["fahr_version"] = FAHR_VERSION;
  m["fast_dds_version"] = FASTRTPS_VERSION_STR;
  m["fast_cdr_version"] = FASTCDR_VERSION_STR;
  m["cyclone_dds_version"] = DDS_VERSION;
  m["recorder_vendor"] = std::string(common::vendor_name(participant.vendor()));
  m["recorder_domain"] = std::to_string(participant.config().domain_id);
  m["recorder_host"] = host_name();
  m["recorder_pid"] = std::to_string(getpid());
  m["start_time_utc"] = utc_now();
  m["start_time_ns"] = std::to_string(common::wall_now_ns());
  m["clock_offset"] = chrony_offset();
  if (!scene_path.empty()) {
    std::ifstream in(scene_path);
    std::stringstream text;
    text << in.rdbuf();
    m["scene_file"] = scene_path;
    m["scene_text"] = in ? text.str() : "(could not read " + scene_path + ")";
  }
  return m;
}

}  // namespace fahr::logger_service
