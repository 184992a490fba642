// The haptic service's run over DDS (see service_loop.h).
#include "fahr/haptic_service/service_loop.h"

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fahr/common/background_publisher.h"
#include "fahr/common/clock.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/publisher.h"
#include "fahr/common/realtime.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/wire_eigen.h"
#include "fahr/haptic_service/run_report.h"
#include "fahr/haptic_service/tissue_snapshot.h"

namespace fahr::haptic_service {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

bool plausible_device_pose(const msg::DevicePose& pose) {
  const auto& p = pose.world_from_stylus();
  const Eigen::Vector3d x = common::to_eigen(p.position_m());
  const Eigen::Vector3d v = common::to_eigen(pose.linear_velocity_mps());
  const auto& q = p.orientation();
  const double q2 = q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z();
  const auto in = [](double value, double low, double high) {
    return std::isfinite(value) && value >= low && value <= high;
  };
  return x.allFinite() && x.norm() <= 2.0 && v.allFinite() && v.norm() <= 100.0 &&
         in(q2, 0.9, 1.1) && in(pose.renderable_force_n(), 0.0, 1e3) &&
         in(pose.max_stiffness_npm(), 0.0, 1e6);
}

void run_realtime(common::Participant& participant, TissueFeed& feed, HapticLoop& loop,
                  common::TickRecorder& recorder, double duration_s, const WaitPolicy& wait,
                  std::shared_ptr<common::AdmissionCounts> pose_admission) {
  // One gateway at a time (another writer refused while it has sent within 1 s),
  // its poses in order and plausible.
  common::Subscriber<msg::DevicePose> poses(
      participant, common::Admission<msg::DevicePose>{.takeover = std::chrono::seconds(1),
                                                      .valid = plausible_device_pose,
                                                      .counts = std::move(pose_admission),
                                                      .wanted = {}});
  common::Publisher<msg::ForceCommand> commands(participant);
  // The ContactSet's write (tens of microseconds: serialisation and send)
  // leaves the tick for a thread of its own, which looks for a new set
  // every 0.5 ms; the FEM takes the newest set at its own rate (5 ms) anyway.
  // The ForceCommand, which the gateway's servo loop waits on, is written
  // on the tick.
  // One per body (its own writer). With several bodies the tick fills the
  // joined tissue's set, split into theirs (split_contacts).
  const HapticSetup& setup = loop.setup();
  const std::size_t bodies = setup.bodies.size();
  std::vector<std::unique_ptr<common::BackgroundPublisher<msg::ContactSet>>> contact_sets;
  for (std::size_t b = 0; b < bodies; ++b) {
    contact_sets.push_back(
        std::make_unique<common::BackgroundPublisher<msg::ContactSet>>(participant, 500us, [] {
          msg::ContactSet contacts;
          contacts.contacts().reserve(msg::MAX_CONTACTS);
          return contacts;
        }));
  }
  msg::ContactSet joined;
  joined.contacts().reserve(msg::MAX_CONTACTS);
  std::array<msg::ContactSet*, kMaxTissueBodies> per_body{};
  msg::ForceCommand command;
  const auto start = Clock::now();
  const auto duration = std::chrono::duration<double>(duration_s);
  RunReport report;
  if (wait.rt_priority > 0) {
    // Opt-in; without the privilege the loop runs on as before.
    const std::string refused = common::request_realtime_priority(wait.rt_priority);
    std::printf("fahr_haptic_service: real-time priority %d: %s\n", wait.rt_priority,
                refused.empty() ? "granted" : refused.c_str());
  }
  std::uint64_t seen = 0;
  std::uint64_t tick = 0;
  std::uint64_t lost_ticks = 0;
  constexpr std::uint64_t kLostSetEveryTicks = 5;
  std::uint64_t polls = 0;
  // The gateway gone or stalled: no DevicePose for the loss timeout. The
  // service holds (sends nothing: nothing asks) and says so once per episode.
  std::int64_t last_pose_ns = 0;
  bool device_silent = false;
  const auto check_device = [&] {
    if (last_pose_ns == 0 || device_silent) return;
    if (common::monotonic_now_ns() - last_pose_ns > kTissueLossTimeoutNs) {
      device_silent = true;
      loop.note_device_silence();
    }
  };
  while (!common::stop_requested()) {
    if (wait.spin) {
      // Check the clock and the stop flag every 4096 polls only.
      if ((++polls & 4095u) == 0) {
        if (duration_s > 0 && Clock::now() - start > duration) break;
        check_device();
      }
      if (!poses.fetch_newest()) continue;
    } else {
      if (duration_s > 0 && Clock::now() - start > duration) break;
      // 20 ms: short enough to notice a stop request or a silent device,
      // long enough not to spin.
      seen = poses.wait_for_samples(seen, 20ms);
      if (!poses.fetch_newest()) {
        check_device();
        continue;
      }
    }
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    last_pose_ns = t0;
    device_silent = false;
    // The FEM is lost once it has sent states and then none for the timeout.
    const std::int64_t last_state_ns = feed.last_state_ns();
    const bool tissue_lost = last_state_ns != 0 && t0 - last_state_ns > kTissueLossTimeoutNs;
    const TissueSnapshot& tissue = feed.newest();
    msg::ContactSet& contacts = bodies > 1 ? joined : contact_sets.front()->back();
    loop.tick(poses.newest(), tissue, command, contacts, tissue_lost);
    if (bodies > 1) {
      for (std::size_t b = 0; b < bodies; ++b) per_body[b] = &contact_sets[b]->back();
      split_contacts(setup, tissue, joined, {per_body.data(), bodies});
    }
    const std::int64_t c1 = common::thread_cpu_now_ns();
    commands.write(command);
    // While the FEM is lost the set repeats the last contacts (HapticLoop::
    // lost_tick): handed over every kLostSetEveryTicks ticks, enough to keep
    // it the FEM's newest, instead of a full set a tick to a FEM that cannot
    // take them (a reliable stream: repairs to a starved reader cost this
    // process CPU).
    lost_ticks = tissue_lost ? lost_ticks + 1 : 0;
    if (lost_ticks % kLostSetEveryTicks == 0 || lost_ticks == 1) {
      for (auto& sets : contact_sets) sets->publish();
    }
    const std::int64_t c2 = common::thread_cpu_now_ns();
    recorder.push({tick++, t0, common::monotonic_now_ns() - t0, c2 - c0});
    report.record(t0, c0, c1, c2, loop.last_phases());
  }
  std::uint64_t handed = 0, written = 0, refused = 0;
  for (const auto& sets : contact_sets) {
    handed += sets->handed();
    written += sets->written();
    refused += sets->refused();
  }
  report.print(handed, written, refused, feed.metrics());
  std::printf("fahr_haptic_service: %s\n", w_summary(loop.metrics()).c_str());
  // Received against the gateway's sequence numbers: a tick runs on the
  // newest pose, so fewer ticks than poses is lateness; a gap is a pose the
  // transport lost.
  std::printf("fahr_haptic_service: DevicePoses received %llu, lost in transport %llu\n",
              static_cast<unsigned long long>(poses.received()),
              static_cast<unsigned long long>(poses.missed()));
  std::printf(
      "fahr_haptic_service: refused DevicePoses: %s; DeformationStates: %s, wrong size or "
      "non-finite %llu\n",
      common::admission_summary(poses.admission_counts()).c_str(),
      common::admission_summary(feed.admission()).c_str(),
      static_cast<unsigned long long>(feed.metrics().bad_states.load(std::memory_order_relaxed)));
}

// One tick per granted base step (the haptic rate is the base rate). At
// step k the pose is the gateway's of step k-1 and the tissue the FEM's
// newest step before k (common/lockstep.h); step 0 has no pose yet and
// answers with no force, so the gateway's step 1 has a command to read.
int run_lockstep(common::Participant& participant, const HapticSetup& setup, HapticLoop& loop,
                 common::TickRecorder& recorder) {
  const scene::Scene& scene = *setup.scene;
  const auto base = scene.run.base_period;
  const auto haptic_steps = static_cast<std::uint64_t>(scene.rates.haptic_period() / base);
  const auto fem_steps = static_cast<std::uint64_t>(scene.rates.fem_period() / base);
  if (haptic_steps != 1) {
    std::fprintf(
        stderr,
        "fahr_haptic_service: lockstep needs the haptic rate to be the base rate (%.0f Hz)\n",
        1e9 / static_cast<double>(base.count()));
    return 2;
  }
  common::StepInput<msg::DevicePose> poses(participant);
  // Per body a reader of its states and a writer of its ContactSets.
  const std::size_t bodies = setup.bodies.size();
  std::vector<std::unique_ptr<common::StepInput<msg::DeformationState>>> states;
  std::vector<std::unique_ptr<common::Publisher<msg::ContactSet>>> contact_sets;
  const std::vector<std::uint32_t> ids = body_ids(setup);
  for (std::size_t b = 0; b < bodies; ++b) {
    states.push_back(std::make_unique<common::StepInput<msg::DeformationState>>(
        participant, common::body_instance<msg::DeformationState>(ids, b, /*strays=*/false)));
    contact_sets.push_back(std::make_unique<common::Publisher<msg::ContactSet>>(
        participant, common::lockstep_output_qos<msg::ContactSet>()));
  }
  common::Publisher<msg::ForceCommand> commands(participant,
                                                common::lockstep_output_qos<msg::ForceCommand>());
  common::LockstepClient client(participant, "haptic");
  client.join();
  TissueDigest digest(setup);
  TissueSnapshot tissue = digest.make_snapshot();
  msg::ForceCommand command;
  // The tick's set (the joined tissue's) and, with several bodies, one per body.
  std::vector<msg::ContactSet> sets(bodies > 1 ? bodies + 1 : 1);
  std::vector<msg::ContactSet*> per_body;
  for (auto& set : sets) set.contacts().reserve(msg::MAX_CONTACTS);
  for (std::size_t b = 0; b < bodies; ++b) {
    msg::ContactSet& set = sets[bodies > 1 ? b + 1 : 0];
    per_body.push_back(&set);
    set.body_id(setup.bodies[b].body->id);
    set.layout_fingerprint(setup.bodies[b].layout_fingerprint);  // step 0 answers with no tick
  }
  msg::ContactSet& contacts = sets.front();
  std::vector<const msg::DeformationState*> body_states(bodies, nullptr);
  common::OutputHash hash;
  std::optional<std::uint64_t> digested_fem_step;
  for (std::uint64_t k = 0; !common::stop_requested() && client.wait_for_grant(k, 60s); ++k) {
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    if (const auto f = common::producer_step_for(k, fem_steps); f && f != digested_fem_step) {
      for (std::size_t b = 0; b < bodies; ++b) {
        body_states[b] = states[b]->wait(*f, 60s);
        if (body_states[b] == nullptr) {
          std::fprintf(stderr,
                       "fahr_haptic_service: DeformationState of body '%s' of FEM step %llu "
                       "never came\n",
                       setup.bodies[b].body->name.c_str(), static_cast<unsigned long long>(*f));
          return 1;
        }
      }
      if (!digest.digest(body_states, tissue)) {
        std::fprintf(
            stderr,
            "fahr_haptic_service: DeformationState of FEM step %llu does not fit the mesh\n",
            static_cast<unsigned long long>(*f));
        return 1;
      }
      digested_fem_step = f;
    }
    bool ticked = false;
    if (const auto p = common::producer_step_for(k, 1)) {
      const msg::DevicePose* pose = poses.wait(*p, 60s);
      if (pose == nullptr) {
        std::fprintf(stderr, "fahr_haptic_service: DevicePose of step %llu never came\n",
                     static_cast<unsigned long long>(*p));
        return 1;
      }
      loop.tick(*pose, tissue, command, contacts);
      ticked = true;
    }
    command.header().sim_step(k);
    command.header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
    contacts.header().sim_step(k);
    contacts.header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
    if (bodies > 1 && ticked) split_contacts(setup, tissue, contacts, per_body);
    commands.write(command);
    hash.add(command);
    for (std::size_t b = 0; b < bodies; ++b) {
      if (bodies > 1) {
        per_body[b]->header().sim_step(k);
        per_body[b]->header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
      }
      contact_sets[b]->write(*per_body[b]);
      hash.add(*per_body[b]);
    }
    recorder.push({k, t0, common::monotonic_now_ns() - t0, common::thread_cpu_now_ns() - c0});
    client.complete_through(k, hash.value());
  }
  std::printf("fahr_haptic_service: lockstep output hash %016llx\n",
              static_cast<unsigned long long>(hash.value()));
  return 0;
}

namespace {

// "'tongue'" or "'tongue' + 'epiglottis'", and "layout 0x..." or
// "layouts 0x..., 0x..." in the same order.
std::string body_names(const HapticSetup& setup) {
  std::string names;
  for (const TissueBody& body : setup.bodies)
    names += (names.empty() ? "'" : " + '") + body.body->name + "'";
  return names;
}

std::string layouts(const HapticSetup& setup) {
  std::string text = setup.bodies.size() > 1 ? "layouts" : "layout";
  for (std::size_t b = 0; b < setup.bodies.size(); ++b) {
    char hex[24];
    std::snprintf(hex, sizeof hex, "%s0x%016llx", b == 0 ? " " : ", ",
                  static_cast<unsigned long long>(setup.bodies[b].layout_fingerprint));
    text += hex;
  }
  return text;
}

std::string field_sources(const HapticSetup& setup) {
  std::vector<const runtime::RigidField*> fields{setup.tool.get()};
  for (const auto& field : setup.anatomy) fields.push_back(field.get());
  return runtime::describe_field_sources(fields);
}

}  // namespace

void print_ready_line(const common::Participant& participant, const HapticSetup& setup,
                      const std::string& collision, bool lockstep, double setup_s) {
  std::printf(
      "fahr_haptic_service: ready: %s, body %s (%zu nodes, %zu spheres, %s), "
      "tool '%s' (%zu surface samples), "
      "%zu tissue / %zu tool obstacles, %s collision, %.0f Hz, %s, set-up %.2f s (%s)\n",
      std::string(common::vendor_name(participant.vendor())).c_str(), body_names(setup).c_str(),
      setup.mesh.node_count(), setup.layout.size(), layouts(setup).c_str(),
      setup.tool->scene_body->name.c_str(), setup.tool_samples.points_m().size(),
      setup.tissue_obstacles.size(), setup.tool_obstacles.size(), collision.c_str(),
      setup.scene->rates.haptic_hz, lockstep ? "lockstep" : "realtime", setup_s,
      field_sources(setup).c_str());
}

void print_end_line(const HapticLoop& loop) {
  const auto& m = loop.metrics();
  std::printf(
      "fahr_haptic_service: %llu ticks on %llu FEM states, lost-track episodes %llu, peak |F| %.3f "
      "N, "
      "worst tick %.0f us\n",
      static_cast<unsigned long long>(m.ticks.load()),
      static_cast<unsigned long long>(m.snapshots.load()),
      static_cast<unsigned long long>(m.lost_track_episodes.load()), m.peak_force_n.load(),
      m.tick_us_peak.load());
}

}  // namespace fahr::haptic_service
