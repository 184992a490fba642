// The services in one process, in lockstep (see stack_sim.h).
#include "fahr/stack_sim/stack_sim.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "fahr/common/clock.h"
#include "fahr/gateway_service/msg_conversion.h"
#include "fahr/scene/plan.h"

namespace fahr::stack_sim {
namespace {

std::vector<std::size_t> deformable_bodies(const scene::Scene& scene) {
  const scene::ServicePlan plan = scene::derive_plan(scene);
  if (plan.fem_bodies.empty())
    throw std::runtime_error("stack_sim: scene '" + scene.name + "' has no deformable body");
  return plan.fem_bodies;
}

}  // namespace

StackSim::StackSim(std::shared_ptr<const scene::Scene> scene, const StackOptions& options)
    : scene_(std::move(scene)),
      base_period_ns_(scene_->run.base_period.count()),
      fem_period_(static_cast<std::uint64_t>(scene_->rates.fem_period() / scene_->run.base_period)),
      haptic_setup_(haptic_service::set_up(*scene_, options.collision,
                                           !options.experiments.haptic_side_anatomy)) {
  for (const std::size_t b : deformable_bodies(*scene_)) {
    fem_setups_.push_back(std::make_unique<fem_service::FemBodySetup>(
        fem_service::set_up_body(*scene_, scene_->bodies[b])));
  }
  if (scene_->rates.haptic_period() != scene_->run.base_period) {
    throw std::runtime_error("stack_sim: the haptic rate must be the base rate of scene '" +
                             scene_->name + "'");
  }
  if (!device::model_by_name("touch_x", gateway_config_.model))
    throw std::runtime_error("stack_sim: no touch_x model");
  gateway_config_.period = scene_->run.base_period;
  const device::HandImpedance hand;
  device::Trajectory script =
      options.keyframes
          ? *options.keyframes
          : device::script_trajectory(options.script, gateway_config_.model.peak_force_n,
                                      hand.stiffness_npm, options.overshoot_factor);
  hand_ =
      std::make_unique<device::SimulatedBackend>(std::move(script), hand, gateway_config_.model,
                                                 gateway_config_.mapping, gateway_config_.period);
  gateway_ = std::make_unique<device::ServoCore>(gateway_config_, *hand_);
  const Experiments& experiments = options.experiments;
  if (experiments.back_off_held_proxy)
    haptic_setup_.response.force_aware.held_proxy = contact::HeldProxy::kBackOff;
  if (experiments.candidate_margin_m)
    haptic_setup_.candidate_margin_m = *experiments.candidate_margin_m;
  haptic_ = std::make_unique<haptic_service::HapticLoop>(haptic_setup_);
  digest_ = std::make_unique<haptic_service::TissueDigest>(haptic_setup_);
  tissue_ = digest_->make_snapshot();
  const std::size_t bodies = fem_setups_.size();
  for (auto& setup : fem_setups_) {
    setup->enforce_anatomy = !experiments.haptic_side_anatomy;
    if (experiments.fem_support_ratio)
      setup->anatomy_settings.support_stiffness_ratio = *experiments.fem_support_ratio;
    if (experiments.fem_anatomy_rounds > 0)
      setup->anatomy_settings.max_rounds = experiments.fem_anatomy_rounds;
    fems_.push_back(std::make_unique<fem_service::ServiceStep>(*setup));
    fem_states_.push_back(&fems_.back()->state());
  }
  contacts_.resize(bodies);
  next_contacts_.resize(bodies);
  split_to_.resize(bodies);
  joined_.contacts().reserve(msg::MAX_CONTACTS);
  for (std::size_t b = 0; b < bodies; ++b) {
    for (auto* set : {&contacts_[b], &next_contacts_[b]}) {
      set->contacts().reserve(msg::MAX_CONTACTS);
      set->body_id(haptic_setup_.bodies[b].body->id);
      // As the haptic service's lockstep loop: step 0 answers with no tick.
      set->layout_fingerprint(haptic_setup_.bodies[b].layout_fingerprint);
    }
  }
  pose_.device_id(options.device_id);
}

double StackSim::largest_node_motion_m(std::size_t b) const {
  const auto& rest = fem_setups_[b]->mesh.rest_positions();
  const auto x = body(b).positions_m();
  double moved = 0.0;
  for (std::size_t n = 0; n < rest.size(); ++n) {
    const Eigen::Vector3d p(x[3 * n], x[3 * n + 1], x[3 * n + 2]);
    moved = std::max(moved, (p - rest[n]).norm());
  }
  return moved;
}

void StackSim::step() {
  const std::uint64_t k = step_;
  const std::int64_t now_ns = static_cast<std::int64_t>(k) * base_period_ns_;

  // Gateway: the haptic service's command of step k - 1 (rendered once as new).
  const device::ForceCommandSample* incoming = nullptr;
  if (k > 0) {
    gateway_service::from_msg(command_, command_sample_);
    incoming = &command_sample_;
  }
  const device::DevicePoseSample& sample =
      gateway_->tick(std::chrono::nanoseconds(now_ns), incoming);
  gateway_service::to_msg(sample, pose_.device_id(), next_pose_);
  next_pose_.header().seq(sample.servo_tick + 1);
  next_pose_.header().sim_step(k);
  next_pose_.header().sim_time_ns(sample.device_time_ns);

  // Haptic: the FEM's newest state before k, the gateway's pose of k - 1.
  const std::size_t bodies = fems_.size();
  if (fem_published_) {
    digest_->digest(fem_states_, tissue_);
    fem_published_ = false;
  }
  if (k > 0) {
    const std::int64_t cpu0 = common::thread_cpu_now_ns();
    haptic_->tick(pose_, tissue_, next_command_, bodies > 1 ? joined_ : next_contacts_.front());
    if (bodies > 1) {
      for (std::size_t b = 0; b < bodies; ++b) split_to_[b] = &next_contacts_[b];
      haptic_service::split_contacts(haptic_setup_, tissue_, joined_, split_to_);
    }
    haptic_tick_cpu_.record(std::chrono::nanoseconds(common::thread_cpu_now_ns() - cpu0));
  }
  next_command_.header().seq(k + 1);
  next_command_.header().sim_step(k);
  next_command_.header().sim_time_ns(now_ns);
  // Numbered as the haptic service's participant numbers them: one sequence
  // for the topic, every body's set each step, in the bodies' order (the FEM
  // reports the number of the set it applied).
  for (std::size_t b = 0; b < bodies; ++b) {
    msg::ContactSet& set = next_contacts_[b];
    set.header().seq(bodies * k + b + 1);
    set.header().sim_step(k);
    set.header().sim_time_ns(now_ns);
  }

  // FEM, at its period: the haptic service's contacts of k - 1, each body's.
  fem_stepped_ = common::executes_at(k, fem_period_);
  if (fem_stepped_) {
    std::chrono::nanoseconds thread{0};
    std::chrono::nanoseconds background{0};
    FemStepCpu parts;
    for (std::size_t b = 0; b < bodies; ++b) {
      fem_service::ServiceStep& fem = *fems_[b];
      if (k > 0) fem.take(contacts_[b], contacts_[b].header().seq());
      const std::int64_t cpu0 = common::thread_cpu_now_ns();
      fem.step();
      // The step's thread and the background factorisation since the last step.
      thread += std::chrono::nanoseconds(common::thread_cpu_now_ns() - cpu0);
      const fem::StepParts& p = fem.last_report().cpu;
      parts.parts.forces_ns += p.forces_ns;
      parts.parts.system_ns += p.system_ns;
      parts.parts.solve_ns += p.solve_ns;
      parts.parts.line_search_ns += p.line_search_ns;
      parts.parts.compliance_ns += p.compliance_ns;
      parts.parts.projection_ns += p.projection_ns;
      parts.parts.supports_ns += p.supports_ns;
      background += std::chrono::nanoseconds(fem.take_background_cpu_ns());
      fem.state().header().sim_step(k);
      fem.state().header().sim_time_ns(now_ns);
      fem_hash_.add(fem.state());
    }
    fem_step_thread_cpu_.record(thread);
    parts.thread_ns = thread.count();
    fem_step_parts_.push_back(parts);
    fem_background_cpu_ += background;
    last_fem_step_cpu_ = thread + background;
    fem_step_cpu_.record(last_fem_step_cpu_);
  }

  // Publish: what step k + 1 reads.
  std::swap(pose_, next_pose_);
  std::swap(command_, next_command_);
  std::swap(contacts_, next_contacts_);
  gateway_hash_.add(pose_);
  haptic_hash_.add(command_);
  for (const msg::ContactSet& set : contacts_) haptic_hash_.add(set);
  fem_published_ = fem_stepped_;
  ++step_;
}

}  // namespace fahr::stack_sim
