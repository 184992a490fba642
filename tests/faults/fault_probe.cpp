// fault_probe: listens to a running station and writes every DevicePose and
// ForceCommand it receives, one line each, for fault_test.sh's analysis:
//
//   P <wall ns> <gateway writer> <servo tick> <safety state> <|F| rendered N> <Fx> <Fy> <Fz> <seq>
//     <source ns>
//   C <wall ns> <haptic writer> <answered pose seq> <reason> <|F| commanded N> <seq> <source ns>
//   S <wall ns> <FEM writer> <FEM step> <seq> <source ns>     (with --states)
//
// <wall ns> is when the probe received the sample, <seq> and <source ns>
// the writer's header (its count of writes and when it wrote this one):
// a probe that lags or drops samples still reads the writer's own rate.
//
//   fault_probe --duration-s S --out FILE [--dds V] [--domain N]   (SIGINT ends it early)
//
// The DevicePose's rendered force is what the device got on that servo
// tick, so consecutive servo ticks give the force step per tick.
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/wire_eigen.h"

namespace {

using namespace fahr;

struct Line {
  char kind;
  std::int64_t wall_ns;
  std::uint32_t writer;
  std::uint64_t count;  // servo tick or answered pose seq
  int state;            // safety state or reason
  double f[4];
  std::uint64_t seq;
  std::int64_t source_ns;
};

}  // namespace

int main(int argc, char** argv) {
  fahr::cli::App app{"fault_test's listener: DevicePose and ForceCommand, one line each"};
  std::string dds, domain, out_path;
  double duration_s = 10;
  app.add_option("--duration-s", duration_s, "how long to listen");
  app.add_option("--out", out_path, "file to write")->required();
  app.add_option("--dds", dds, "DDS vendor");
  app.add_option("--domain", domain, "DDS domain id");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  bool with_states = false;
  app.add_flag("--states", with_states, "also a line per DeformationState");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  common::Participant participant(
      common::transport_config_from(dds, domain, "", "fault_probe", security));
  std::mutex mutex;
  std::vector<Line> lines;
  lines.reserve(static_cast<std::size_t>(duration_s * 2500) + 1000);
  const auto qos = common::QosProfile::for_role(common::TopicRole::kServoStream);
  common::Subscriber<msg::DevicePose> poses(
      participant, qos, common::TopicTraits<msg::DevicePose>::kName,
      [&](const msg::DevicePose& p, const common::SampleInfo& info) {
        const Eigen::Vector3d f = common::to_eigen(p.rendered_force_n());
        std::lock_guard lock(mutex);
        lines.push_back({'P',
                         info.receive_time_ns,
                         p.header().writer_id(),
                         p.servo_tick(),
                         static_cast<int>(p.safety_state()),
                         {f.norm(), f.x(), f.y(), f.z()},
                         p.header().seq(),
                         p.header().source_time_ns()});
      });
  common::Subscriber<msg::ForceCommand> commands(
      participant, qos, common::TopicTraits<msg::ForceCommand>::kName,
      [&](const msg::ForceCommand& c, const common::SampleInfo& info) {
        const Eigen::Vector3d f = common::to_eigen(c.force_n());
        std::lock_guard lock(mutex);
        lines.push_back({'C',
                         info.receive_time_ns,
                         c.header().writer_id(),
                         c.answered_pose_seq(),
                         static_cast<int>(c.reason()),
                         {f.norm(), 0, 0, 0},
                         c.header().seq(),
                         c.header().source_time_ns()});
      });
  std::unique_ptr<common::Subscriber<msg::DeformationState>> states;
  if (with_states) {
    states = std::make_unique<common::Subscriber<msg::DeformationState>>(
        participant, common::QosProfile::for_role(common::TopicRole::kStateStream),
        common::TopicTraits<msg::DeformationState>::kName,
        [&](const msg::DeformationState& s, const common::SampleInfo& info) {
          std::lock_guard lock(mutex);
          lines.push_back({'S',
                           info.receive_time_ns,
                           s.header().writer_id(),
                           s.step(),
                           0,
                           {0, 0, 0, 0},
                           s.header().seq(),
                           s.header().source_time_ns()});
        });
  }
  common::install_stop_handlers();
  std::printf("fault_probe: listening for %.1f s (or until SIGINT)\n", duration_s);
  std::fflush(stdout);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (!common::stop_requested() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::lock_guard lock(mutex);
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (out == nullptr) {
    std::fprintf(stderr, "fault_probe: cannot write %s\n", out_path.c_str());
    return 1;
  }
  for (const Line& l : lines) {
    if (l.kind == 'P') {
      std::fprintf(out, "P %lld %u %llu %d %.6f %.6f %.6f %.6f", static_cast<long long>(l.wall_ns),
                   l.writer, static_cast<unsigned long long>(l.count), l.state, l.f[0], l.f[1],
                   l.f[2], l.f[3]);
    } else if (l.kind == 'S') {
      std::fprintf(out, "S %lld %u %llu", static_cast<long long>(l.wall_ns), l.writer,
                   static_cast<unsigned long long>(l.count));
    } else {
      std::fprintf(out, "C %lld %u %llu %d %.6f", static_cast<long long>(l.wall_ns), l.writer,
                   static_cast<unsigned long long>(l.count), l.state, l.f[0]);
    }
    std::fprintf(out, " %llu %lld\n", static_cast<unsigned long long>(l.seq),
                 static_cast<long long>(l.source_ns));
  }
  std::fclose(out);
  std::printf("fault_probe: %zu lines written to %s\n", lines.size(), out_path.c_str());
  return 0;
}
