// One property run: a random bounded device trajectory against the small
// block, and the checks of property_run.h.
#include "fahr/contact/sim/property_run.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "fahr/contact/sim/lockstep_run.h"

namespace fahr::contact::sim {
namespace {

constexpr double kDt = 0.001;
constexpr int kFastPeriodTicks = 5;   // FEM at 200 Hz
constexpr int kSlowPeriodTicks = 20;  // FEM at 50 Hz
constexpr double kRampS = 0.15;       // the device eases in over this, s

struct Sinusoid {
  double amplitude_m, frequency_hz, phase_rad;
};

// Bounded by construction: a descent of at most 10 mm below the surface and
// nine sinusoids of at most 4 mm, 0.5-5.5 Hz, three per axis.
struct Trajectory {
  std::array<Sinusoid, 9> waves{};
  double depth_m = 0.0;  // how far below the surface the tool centre goes, m
  double tool_radius_m = 0.0;

  Eigen::Vector3d at(std::uint64_t tick) const {
    const double t = kDt * static_cast<double>(tick);
    // Starts 4 mm above the spheres and ramps in.
    const double ramp = std::min(1.0, t / kRampS);
    Eigen::Vector3d p(0.0, 0.004 + tool_radius_m - depth_m * ramp, 0.0);
    for (std::size_t axis = 0; axis < 3; ++axis) {
      for (std::size_t j = 0; j < 3; ++j) {
        const Sinusoid& w = waves[3 * axis + j];
        p[static_cast<Eigen::Index>(axis)] +=
            ramp * w.amplitude_m *
            std::sin(2 * std::numbers::pi * w.frequency_hz * t + w.phase_rad);
      }
    }
    return p;
  }
};

// Tracks the penetration of active constraints over consecutive FEM steps.
class PersistenceWindow {
 public:
  explicit PersistenceWindow(int persistent_steps)
      : window_(static_cast<std::size_t>(persistent_steps) + 1) {}
  // The smallest depth over the last window_ steps once that many have
  // passed: a depth every one of them kept.
  double push(double depth_m) {
    depths_[next_ % kCapacity] = depth_m;
    ++next_;
    if (next_ < window_) return 0.0;
    double kept = depth_m;
    for (std::size_t i = 1; i < window_; ++i)
      kept = std::min(kept, depths_[(next_ - 1 - i) % kCapacity]);
    return kept;
  }

 private:
  static constexpr std::size_t kCapacity = 16;
  std::size_t window_;
  std::array<double, kCapacity> depths_{};
  std::size_t next_ = 0;
};

}  // namespace

PropertyScenes::PropertyScenes(std::string& error)
    : fast_(make_small_scene(kFastPeriodTicks * kDt, error)),
      slow_(make_small_scene(kSlowPeriodTicks * kDt, error)) {
  if (error.empty() && (!fast_.fem || !slow_.fem)) error = "property scenes: FEM set-up failed";
}

std::uint64_t property_seed(int run) {
  return static_cast<std::uint64_t>(run) * 7919u + 13u;
}

PropertyRunResult run_property(int run, double seconds, PropertyScenes& scenes,
                               const PropertyLimits& limits) {
  PropertyRunResult result;
  result.run = run;
  result.seed = property_seed(run);
  std::mt19937_64 rng(result.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SmallScene& scene = scenes.for_run(run);
  if (!scene.fem->reset()) {
    result.failure = "the FEM did not reset to rest";
    return result;
  }

  LockstepConfig config;
  config.method = Method::kForceAware;
  config.fem_period_ticks = run % 2 == 1 ? kSlowPeriodTicks : kFastPeriodTicks;
  config.dt_s = kDt;
  config.tool = ToolShape{ToolKind::kBall, 0.002 + 0.003 * unit(rng), 0.002};
  config.obstacles.push_back(
      PlaneObstacle{1, Eigen::Vector3d(0.006, 0, 0), Eigen::Vector3d(-1, 0, 0)});
  config.renderable_force_n = 0.1 + 0.6 * unit(rng);
  config.response.coupling.stiffness_npm = 200.0 + 1280.0 * unit(rng);
  Trajectory trajectory;
  trajectory.tool_radius_m = config.tool.radius_m;
  for (Sinusoid& w : trajectory.waves)
    w = Sinusoid{0.004 * unit(rng), 0.5 + 5.0 * unit(rng), 2 * std::numbers::pi * unit(rng)};
  trajectory.depth_m = 0.002 + 0.008 * unit(rng);
  result.limit_n = config.renderable_force_n;

  const double limit = config.renderable_force_n;
  PersistenceWindow persistence(limits.persistent_steps);
  auto fail = [&](const std::string& why) {
    if (result.failure.empty()) result.failure = why;
  };
  LockstepRun lockstep(config, *scene.fem, trajectory.at(0));
  const auto ticks = static_cast<std::uint64_t>(std::llround(seconds / kDt));
  lockstep.run(
      ticks, [&](std::uint64_t k) { return trajectory.at(k); },
      [&](const TickRecord& rec) {
        if (!rec.finite || (rec.fem_stepped && !rec.fem.finite)) {
          result.finite = false;
          fail("not finite at tick " + std::to_string(rec.tick));
        }
        result.froze = result.froze || rec.lost_track;
        result.max_reaction_n = std::max(result.max_reaction_n, rec.tissue_reaction_n);
        if (rec.tissue_reaction_n > limits.reaction_slack * limit) {
          fail("tissue reaction " + std::to_string(rec.tissue_reaction_n) + " N over the limit " +
               std::to_string(limit) + " N at tick " + std::to_string(rec.tick) +
               (rec.lost_track ? " (lost track)" : ""));
        }
        const double command = rec.force_n.norm();
        result.max_command_n = std::max(result.max_command_n, command);
        if (command > limits.command_slack * limit) {
          fail("ForceCommand force " + std::to_string(command) + " N over the limit " +
               std::to_string(limit) + " N at tick " + std::to_string(rec.tick));
        }
        if (rec.fem_stepped) {
          result.max_force_only_penetration_m =
              std::max(result.max_force_only_penetration_m, rec.force_only_penetration_m);
          const double kept = persistence.push(rec.active_penetration_m);
          result.max_persistent_penetration_m = std::max(result.max_persistent_penetration_m, kept);
          if (kept > limits.penetration_tolerance_m) {
            fail("active penetration of " + std::to_string(kept) + " m kept for " +
                 std::to_string(limits.persistent_steps + 1) + " FEM steps at tick " +
                 std::to_string(rec.tick));
          }
        }
      });
  return result;
}

}  // namespace fahr::contact::sim
