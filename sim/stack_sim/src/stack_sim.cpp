// The services in one process, in lockstep (see stack_sim.h).
#include "fahr/stack_sim/stack_sim.h"

#include <stdexcept>

#include "fahr/common/clock.h"
#include "fahr/gateway_service/msg_conversion.h"
#include "fahr/scene/plan.h"

namespace fahr::stack_sim {
namespace {

const scene::Body& deformable_body(const scene::Scene& scene) {
  const scene::ServicePlan plan = scene::derive_plan(scene);
  if (plan.fem_bodies.size() != 1) {
    throw std::runtime_error("stack_sim: scene '" + scene.name +
                             "' needs exactly one deformable body");
  }
  return scene.bodies[plan.fem_bodies.front()];
}

}  // namespace

StackSim::StackSim(std::shared_ptr<const scene::Scene> scene, const StackOptions& options)
    : scene_(std::move(scene)),
      base_period_ns_(scene_->run.base_period.count()),
      fem_period_(static_cast<std::uint64_t>(scene_->rates.fem_period() / scene_->run.base_period)),
      haptic_setup_(haptic_service::set_up(*scene_, options.collision,
                                           !options.experiments.haptic_side_anatomy)),
      fem_setup_(fem_service::set_up_body(*scene_, deformable_body(*scene_))) {
  if (scene_->rates.haptic_period() != scene_->run.base_period) {
    throw std::runtime_error("stack_sim: the haptic rate must be the base rate of scene '" +
                             scene_->name + "'");
  }
  if (!device::model_by_name("touch_x", gateway_config_.model))
    throw std::runtime_error("stack_sim: no touch_x model");
  gateway_config_.period = scene_->run.base_period;
  const device::HandImpedance hand;
  device::Trajectory script =
      options.script == device::Script::kOvershoot
          ? device::overshoot_script(gateway_config_.model.peak_force_n, hand.stiffness_npm,
                                     options.overshoot_factor)
          : device::intubation_script();
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
  fem_setup_.enforce_anatomy = !experiments.haptic_side_anatomy;
  if (experiments.fem_support_ratio)
    fem_setup_.anatomy_settings.support_stiffness_ratio = *experiments.fem_support_ratio;
  if (experiments.fem_anatomy_rounds > 0)
    fem_setup_.anatomy_settings.max_rounds = experiments.fem_anatomy_rounds;
  fem_ = std::make_unique<fem_service::ServiceStep>(fem_setup_);
  contacts_.contacts().reserve(msg::MAX_CONTACTS);
  next_contacts_.contacts().reserve(msg::MAX_CONTACTS);
  contacts_.body_id(haptic_setup_.deformable->id);
  next_contacts_.body_id(haptic_setup_.deformable->id);
  // As the haptic service's lockstep loop: step 0 answers with no tick.
  contacts_.layout_fingerprint(haptic_->layout_fingerprint());
  next_contacts_.layout_fingerprint(haptic_->layout_fingerprint());
  pose_.device_id(options.device_id);
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
  if (fem_published_) {
    digest_->digest(fem_->state(), tissue_);
    fem_published_ = false;
  }
  if (k > 0) {
    const std::int64_t cpu0 = common::thread_cpu_now_ns();
    haptic_->tick(pose_, tissue_, next_command_, next_contacts_);
    haptic_tick_cpu_.record(std::chrono::nanoseconds(common::thread_cpu_now_ns() - cpu0));
  }
  next_command_.header().seq(k + 1);
  next_command_.header().sim_step(k);
  next_command_.header().sim_time_ns(now_ns);
  next_contacts_.header().seq(k + 1);
  next_contacts_.header().sim_step(k);
  next_contacts_.header().sim_time_ns(now_ns);

  // FEM, at its period: the haptic service's contacts of k - 1.
  fem_stepped_ = common::executes_at(k, fem_period_);
  if (fem_stepped_) {
    if (k > 0) fem_->take(contacts_, contacts_.header().seq());
    const std::int64_t cpu0 = common::thread_cpu_now_ns();
    fem_->step();
    // The step's thread and the background factorisation since the last step.
    const std::chrono::nanoseconds thread(common::thread_cpu_now_ns() - cpu0);
    const std::chrono::nanoseconds background(fem_->take_background_cpu_ns());
    fem_step_thread_cpu_.record(thread);
    fem_background_cpu_ += background;
    last_fem_step_cpu_ = thread + background;
    fem_step_cpu_.record(last_fem_step_cpu_);
    fem_->state().header().sim_step(k);
    fem_->state().header().sim_time_ns(now_ns);
    fem_hash_.add(fem_->state());
  }

  // Publish: what step k + 1 reads.
  std::swap(pose_, next_pose_);
  std::swap(command_, next_command_);
  std::swap(contacts_, next_contacts_);
  gateway_hash_.add(pose_);
  haptic_hash_.add(command_);
  haptic_hash_.add(contacts_);
  fem_published_ = fem_stepped_;
  ++step_;
}

}  // namespace fahr::stack_sim
