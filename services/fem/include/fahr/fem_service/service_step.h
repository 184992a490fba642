// What one FEM service step is, without transport: take the newest wire
// ContactSet, step the body under the contact contract (fem::ContactStep),
// and fill the DeformationState that reports it, with the compliance block
// and the free-motion centres of the spheres the haptic service works with.
// The service main moves these messages over DDS; tests and tools can step
// the service's own code in one process, in lockstep with a haptic side.
// Everything is sized at construction: a step allocates nothing once the
// containers have reached their largest size.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "contact_set.h"
#include "deformation_state.h"
#include "fahr/common/subscriber.h"
#include "fahr/fem/contact_set.h"
#include "fahr/fem/contact_step.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/layout_check.h"

namespace fahr::fem_service {

class ServiceStep {
 public:
  // `setup` must outlive this object.
  explicit ServiceStep(FemBodySetup& setup);

  // Times passed as kBodyClock are the body's simulated time at its
  // current step (lockstep, in-process harnesses); a real-time loop passes
  // its monotonic clock, ns.
  static constexpr std::int64_t kBodyClock = -1;

  // The newest ContactSet, its sample sequence number and when it arrived;
  // kept until the next one. It is applied until the scene's
  // max_contact_age has passed since it arrived with no newer one (the
  // haptic service silent: the tongue is then released), whatever state it
  // was computed on, unless that state is older than the body's last
  // divergence reset.
  // A set of another sphere layout than the body's (layout_check.h) is
  // refused: the steps until the next set apply no contacts.
  // A set with a non-finite number (all_finite), or naming a sphere the
  // layout does not have, is refused and counted the same way: nothing of it
  // is used.
  void take(const msg::ContactSet& wire, std::uint64_t seq, std::int64_t received_ns = kBodyClock);

  // One FEM step at `now_ns` and the DeformationState that reports it (the
  // header is the caller's: its clock and step numbering depend on the mode).
  void step(std::int64_t now_ns = kBodyClock);

  msg::DeformationState& state() { return state_; }
  const msg::DeformationState& state() const { return state_; }
  const fem::StepReport& last_report() const { return last_report_; }
  const fem::ContactStep& contact_step() const { return contact_step_; }

  const FemBodySetup& setup() const { return setup_; }
  // Refused ContactSets and their error (the service's reporter takes it).
  LayoutCheck& layout_check() { return layout_check_; }
  const LayoutCheck& layout_check() const { return layout_check_; }
  std::uint64_t stale_sets() const { return stale_sets_; }
  // Of those, the steps a newer set followed: the sender was late, not gone.
  // A run's end, where the haptic service stops sending before the FEM
  // stops stepping, leaves its last set stale for good and is not among them.
  std::uint64_t stale_sets_followed() const { return stale_followed_; }
  std::uint64_t inverted_max() const { return inverted_max_; }
  // Steps after which the body had diverged and was reset to rest
  // (fem::StepReport::diverged_reset).
  std::uint64_t divergence_resets() const { return divergence_resets_; }
  // Steps the line search shortened (fem::StepReport::line_search_halvings).
  std::uint64_t shortened_steps() const { return shortened_steps_; }
  // Steps whose line search found no downhill step (reported as an error).
  std::uint64_t uphill_steps() const { return uphill_steps_.load(std::memory_order_relaxed); }
  // Steps that refactorised the system matrix (fem::StepReport::refactorised).
  std::uint64_t refactorisations() const { return refactorisations_; }
  // The run's slowest step (wall time of ServiceStep::step) and what it
  // did: where a step past the haptic side's 50 ms loss timeout went.
  struct SlowestStep {
    std::int64_t wall_ns = 0;
    std::uint64_t step = 0;
    bool refactorised = false;
    bool compliance_solved = false;  // W's block solved (not reused)
    std::size_t tool_contacts = 0;   // contacts of the set applied (0: none)
    int projection_sweeps = 0;
    int anatomy_rounds = 0;
    int anatomy_nodes = 0;
    int inverted_elements = 0;
  };
  const SlowestStep& slowest_step() const { return slowest_; }
  // Nodes let back through a bone on their way home, and node-steps a node
  // spent beyond a bone, left alone by it (fem obstacle_projection.h).
  std::uint64_t anatomy_returned() const { return anatomy_returned_; }
  std::uint64_t anatomy_beyond_steps() const { return anatomy_beyond_steps_; }

  // ContactSets refused for a non-finite number, and steps whose linear
  // solve failed or gave a non-finite velocity (the body then kept its
  // positions with zero velocity, fem::StepReport::solve_failed).
  std::uint64_t non_finite_sets() const { return non_finite_sets_.load(std::memory_order_relaxed); }
  // ContactSets refused because they answer a step this body has not
  // reached: sets of the haptic service answering an FEM before a restart.
  std::uint64_t ahead_sets() const { return ahead_sets_.load(std::memory_order_relaxed); }
  std::uint64_t unknown_sphere_sets() const {
    return unknown_sphere_sets_.load(std::memory_order_relaxed);
  }
  // Refusals of the real-time ContactSet reader: another writer than the
  // haptic service it follows (common::Admission; fem_loop.cpp).
  const std::shared_ptr<common::AdmissionCounts>& contact_admission() const {
    return contact_admission_;
  }
  std::uint64_t failed_solves() const { return failed_solves_.load(std::memory_order_relaxed); }
  // What went wrong since the last call, one sentence per kind (a layout
  // refused, sets with non-finite numbers, failed solves, resets after
  // divergence), for the service's ServiceEvents; called off the step.
  void take_errors(std::vector<std::string>& errors);

  // CPU the body's background factorisation thread used since the last
  // call, ns: with the step thread's own, the step's CPU on all threads.
  std::int64_t take_background_cpu_ns();

  // The service's own ServiceStatus metrics.
  void metrics(std::vector<std::pair<std::string, double>>& out) const;

 private:
  void fill_compliance();

  FemBodySetup& setup_;
  fem::ContactStep contact_step_;
  LayoutCheck layout_check_;
  fem::ContactSet contacts_;
  bool have_contacts_ = false;
  std::int64_t received_ns_ = 0;  // when contacts_ arrived (take's clock)
  std::int64_t max_age_ns_ = 0;   // the scene's max_contact_age
  std::uint64_t applied_contact_seq_ = 0;
  msg::DeformationState state_;
  fem::StepReport last_report_;
  std::uint64_t inverted_max_ = 0;
  std::uint64_t divergence_resets_ = 0;
  std::uint64_t shortened_steps_ = 0;
  SlowestStep slowest_;
  // The body's step at its last reset: a ContactSet computed on an earlier
  // state describes a tongue that no longer exists.
  std::uint64_t reset_step_ = 0;
  std::uint64_t refactorisations_ = 0;
  std::atomic<std::uint64_t> non_finite_sets_{0};
  std::atomic<std::uint64_t> ahead_sets_{0};
  std::atomic<std::uint64_t> unknown_sphere_sets_{0};
  std::shared_ptr<common::AdmissionCounts> contact_admission_ =
      std::make_shared<common::AdmissionCounts>();
  std::atomic<std::uint64_t> failed_solves_{0};
  std::atomic<std::uint64_t> uphill_steps_{0};
  std::atomic<std::uint64_t> resets_{0};
  // What take_errors() has said so far (its caller's thread only).
  std::uint64_t non_finite_said_ = 0;
  std::uint64_t ahead_said_ = 0;
  std::uint64_t unknown_said_ = 0;
  std::uint64_t failed_said_ = 0;
  std::uint64_t uphill_said_ = 0;
  std::uint64_t resets_said_ = 0;
  std::uint64_t anatomy_returned_ = 0;
  std::uint64_t anatomy_beyond_steps_ = 0;
  double anatomy_depth_max_m_ = 0.0;
  std::uint64_t stale_sets_ = 0;
  std::uint64_t stale_run_ = 0;  // stale steps since the last usable set
  std::uint64_t stale_followed_ = 0;
  std::int64_t background_cpu_taken_ns_ = 0;
};

}  // namespace fahr::fem_service
