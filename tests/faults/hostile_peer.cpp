// hostile_peer: a participant allowed on the station's domain (no DDS
// Security) that sends hostile samples on every stream the services read,
// round robin, as fast as it can (or at --rate-hz):
//
//   DevicePose       non-finite, huge (1e30 m), a sequence that runs
//                    backwards, a well-formed pose of its own
//   ForceCommand     non-finite, huge (1e30 N), a well-formed 2 N push
//   ContactSet       a sphere id no layout has, non-finite, well-formed
//   DeformationState ten nodes (the wrong size), non-finite
//
// It stamps its own headers (seq, writer_id) through the vendor's writer,
// as any DDS participant can. Prints, at the end,
//   "hostile: wrote N samples in S s (DevicePose a, ForceCommand b, ContactSet c, DeformationState
//   d)".
//
// With --on-off-s T it floods for T seconds, rests T seconds, and so on,
// printing "hostile: on <wall ns> <wall ns>" for each flood, so a run can
// compare the station's rates with and without it, interleaved.
//
//   hostile_peer --seconds S [--dds V] [--domain N] [--rate-hz R] [--on-off-s T]
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <thread>

#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/common/topics.h"

namespace {

using namespace fahr;

// A writer whose samples carry the headers the caller chose.
template <class T>
class ForgingWriter {
 public:
  explicit ForgingWriter(common::Participant& participant) {
    common::detail::EndpointSpec spec{&common::detail::type_support<T>(),
                                      std::string(common::TopicTraits<T>::kName),
                                      common::QosProfile::for_role(common::TopicTraits<T>::kRole)};
    writer_ = participant.backend().create_writer(spec);
  }
  void write(T& sample, std::uint64_t seq) {
    sample.header().seq(seq);
    sample.header().writer_id(0xbad);
    const std::int64_t now_ns = common::wall_now_ns();
    sample.header().source_time_ns(now_ns);
    writer_->write(&sample, now_ns);
    ++written;
  }
  std::uint64_t written = 0;

 private:
  std::unique_ptr<common::detail::WriterBackend> writer_;
};

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

}  // namespace

int main(int argc, char** argv) {
  fahr::cli::App app{"a participant that sends hostile samples on the station's streams"};
  std::string dds, domain;
  double seconds = 5, rate_hz = 0;
  app.add_option("--seconds", seconds, "how long");
  app.add_option("--dds", dds, "DDS vendor");
  app.add_option("--domain", domain, "DDS domain id");
  app.add_option("--rate-hz", rate_hz, "samples per second in all (0: as fast as it can)");
  double on_off_s = 0;
  app.add_option("--on-off-s", on_off_s, "flood this long, rest this long, and so on (0: always)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    common::Participant participant(common::transport_config_from(dds, domain, "", "hostile_peer"));
    ForgingWriter<msg::DevicePose> poses(participant);
    ForgingWriter<msg::ForceCommand> commands(participant);
    ForgingWriter<msg::ContactSet> sets(participant);
    ForgingWriter<msg::DeformationState> states(participant);

    msg::DevicePose pose;
    pose.world_from_stylus().orientation().w(1.0);
    pose.renderable_force_n(7.9);
    msg::ForceCommand command;
    msg::ContactSet set;
    set.contacts().resize(1);
    set.contacts()[0].normal().z(1.0);
    set.contacts()[0].kind(msg::CONTACT_TOOL);
    set.contacts()[0].state(msg::CONSTRAINT_ACTIVE);
    set.world_from_tool().orientation().w(1.0);
    msg::DeformationState state;
    state.positions_m().resize(30);
    state.velocities_mps().resize(30);

    const auto start = std::chrono::steady_clock::now();
    const auto end = start + std::chrono::duration<double>(seconds);
    const auto gap = rate_hz > 0 ? std::chrono::duration<double>(1.0 / rate_hz)
                                 : std::chrono::duration<double>(0);
    auto next = start;
    std::uint64_t n = 0;
    const auto phase = std::chrono::duration<double>(on_off_s);
    auto phase_end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(phase);
    std::int64_t on_since_ns = common::wall_now_ns();
    while (std::chrono::steady_clock::now() < end) {
      if (on_off_s > 0 && std::chrono::steady_clock::now() >= phase_end) {
        std::printf("hostile: on %lld %lld\n", static_cast<long long>(on_since_ns),
                    static_cast<long long>(common::wall_now_ns()));
        std::this_thread::sleep_until(
            phase_end + std::chrono::duration_cast<std::chrono::steady_clock::duration>(phase));
        phase_end += std::chrono::duration_cast<std::chrono::steady_clock::duration>(2 * phase);
        on_since_ns = common::wall_now_ns();
        next = std::chrono::steady_clock::now();
        continue;
      }
      const std::uint64_t seq = n + 1;
      switch (n % 12) {
        case 0:  // non-finite pose
          pose.world_from_stylus().position_m().x(kNan);
          poses.write(pose, seq);
          break;
        case 1:  // a pose a kilometre cubed away
          pose.world_from_stylus().position_m().x(1e30);
          poses.write(pose, seq);
          break;
        case 2:  // a sequence that runs backwards
          pose.world_from_stylus().position_m().x(0.05);
          poses.write(pose, 1'000'000'000 - n);
          break;
        case 3:  // well-formed, near the tongue
          pose.world_from_stylus().position_m().x(0.01);
          poses.write(pose, seq);
          break;
        case 4:
          command.force_n().z(kNan);
          commands.write(command, seq);
          break;
        case 5:
          command.force_n().z(1e30);
          commands.write(command, seq);
          break;
        case 6:  // a well-formed push
          command.force_n().z(2.0);
          commands.write(command, seq);
          break;
        case 7:
          set.contacts()[0].sphere_id(std::numeric_limits<std::uint32_t>::max());
          set.contacts()[0].force_n(1.0);
          sets.write(set, seq);
          break;
        case 8:
          set.contacts()[0].sphere_id(0);
          set.contacts()[0].force_n(kNan);
          sets.write(set, seq);
          break;
        case 9:
          set.contacts()[0].force_n(5.0);
          sets.write(set, seq);
          break;
        case 10:  // ten nodes: no body of the scene
          state.positions_m()[0] = 0.0f;
          states.write(state, seq);
          break;
        default:
          state.positions_m()[0] = std::numeric_limits<float>::quiet_NaN();
          states.write(state, seq);
          break;
      }
      ++n;
      if (gap.count() > 0) {
        next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(gap);
        std::this_thread::sleep_until(next);
      }
    }
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "hostile: wrote %llu samples in %.1f s (DevicePose %llu, ForceCommand %llu, ContactSet "
        "%llu, DeformationState %llu)\n",
        static_cast<unsigned long long>(n), took, static_cast<unsigned long long>(poses.written),
        static_cast<unsigned long long>(commands.written),
        static_cast<unsigned long long>(sets.written),
        static_cast<unsigned long long>(states.written));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hostile_peer: %s\n", e.what());
    return 1;
  }
}
