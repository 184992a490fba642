// The glottic view service: newest FEM state and ContactSet -> GlotticView.
#include "fahr/visualizer_service/glottic_view_service.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/clock.h"
#include "fahr/common/publisher.h"
#include "fahr/common/topics.h"
#include "fahr/glottic_view/blade_from_contacts.h"
#include "glottic_viewPubSubTypes.h"

namespace fahr::visualizer_service {

struct GlotticViewService::Impl {
  Impl(const scene::Scene& scene, LiveState& store, common::Participant* participant)
      : view(glottic_view::glottic_view_from_scene(scene)), live(store) {
    const auto tool = scene.tool_index();
    if (!tool) throw std::invalid_argument(scene.source_name + ": the glottic view needs a tool");
    tool_body_id = scene.bodies[*tool].id;
    // Until a ContactSet says where the blade is, it is where the scene puts it.
    const scene::Pose& start = scene.bodies[*tool].pose;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = start.orientation.toRotationMatrix();
    pose.translation() = start.position_m;
    world_from_tool = pose;
    if (participant != nullptr) publisher.emplace(*participant);
    positions.resize(view.deformable_body_ids.size());
    have_state.assign(view.deformable_body_ids.size(), false);
  }

  glottic_view::SceneGlotticView view;
  LiveState& live;
  std::uint32_t tool_body_id = 0;
  std::optional<common::Publisher<msg::GlotticView>> publisher;
  // Scratch, kept between views.
  std::vector<Slot> slots;
  std::vector<std::uint64_t> seen;                      // slot versions already read
  std::vector<std::vector<Eigen::Vector3d>> positions;  // per soft body
  std::vector<bool> have_state;
  msg::DeformationState state;
  msg::ContactSet contacts;
  msg::GlotticView sample;
  std::vector<std::uint8_t> bytes;
  std::optional<Eigen::Isometry3d> world_from_tool;  // always set (the scene's pose first)
  double tool_force_n = 0.0;
  std::uint64_t fem_step = 0, haptic_tick = 0, seq = 0;
  std::int64_t sim_time_ns = 0;
  std::uint64_t sim_step = 0;
  mutable std::mutex mutex;
  Stats stats;

  // Reads the changed slots; false if a soft body's state was refused.
  // `changed`: a new FEM state or ContactSet was read.
  bool read_slots(bool& changed);
  void read_contacts(const msg::ContactSet& set);
};

bool GlotticViewService::Impl::read_slots(bool& changed) {
  bool ok = true;
  changed = false;
  if (seen.size() < slots.size()) seen.resize(slots.size(), 0);
  live.collect(slots);
  seen.resize(slots.size(), 0);
  for (std::size_t s = 0; s < slots.size(); ++s) {
    const Slot& slot = slots[s];
    if (slot.version == seen[s]) continue;
    seen[s] = slot.version;
    if (slot.bytes.empty()) continue;
    if (slot.topic == kContactSet || slot.topic == kDeformationState) changed = true;
    if (slot.topic == kContactSet) {
      if (common::decode_cdr<msg::ContactSetPubSubType>(slot.bytes, contacts))
        read_contacts(contacts);
      continue;
    }
    if (slot.topic != kDeformationState) continue;
    if (!common::decode_cdr<msg::DeformationStatePubSubType>(slot.bytes, state)) continue;
    for (std::size_t b = 0; b < view.deformable_body_ids.size(); ++b) {
      if (state.body_id() != view.deformable_body_ids[b]) continue;
      const auto& xyz = state.positions_m();
      const std::size_t nodes = view.deformable_node_counts[b];
      bool finite = xyz.size() == 3 * nodes;
      for (std::size_t i = 0; finite && i < xyz.size(); ++i) finite = std::isfinite(xyz[i]);
      if (!finite) {
        ok = false;
        continue;
      }
      positions[b].resize(nodes);
      for (std::size_t i = 0; i < nodes; ++i)
        positions[b][i] = Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      have_state[b] = true;
      fem_step = state.step();
      sim_time_ns = state.header().sim_time_ns();
      sim_step = state.header().sim_step();
    }
  }
  return ok;
}

void GlotticViewService::Impl::read_contacts(const msg::ContactSet& set) {
  const glottic_view::BladeFromContacts blade = glottic_view::blade_from_contacts(set);
  if (!blade.world_from_tool) return;  // no tool pose: keep the last one
  world_from_tool = blade.world_from_tool;
  tool_force_n = blade.tool_force_n;
  haptic_tick = set.haptic_tick();
}

GlotticViewService::GlotticViewService(const scene::Scene& scene, LiveState& live,
                                       common::Participant* participant)
    : impl_(std::make_unique<Impl>(scene, live, participant)) {}

GlotticViewService::~GlotticViewService() {
  stop();
}

void GlotticViewService::start() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / impl_->view.rate_hz));
  thread_ = std::thread([this, period] {
    auto next = std::chrono::steady_clock::now();
    while (!stop_) {
      next += period;
      std::this_thread::sleep_until(next);
      update();
    }
  });
}

void GlotticViewService::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool GlotticViewService::update() {
  Impl& m = *impl_;
  bool changed = false;
  if (!m.read_slots(changed)) {
    std::lock_guard lock(m.mutex);
    ++m.stats.refused;
  }
  // The same geometry gives the same view: none until something moved (a
  // paused replay, a sleeping tongue with the blade away).
  if (!changed) return false;
  for (const bool have : m.have_state) {
    if (!have) return false;
  }
  std::vector<std::span<const Eigen::Vector3d>> soft(m.positions.begin(), m.positions.end());
  const Eigen::Vector3d eye = *m.world_from_tool * m.view.eye_in_tool_m;
  glottic_view::ViewScore score;
  try {
    score = m.view.view.score(eye, m.world_from_tool, soft);
  } catch (const std::invalid_argument&) {
    std::lock_guard lock(m.mutex);
    ++m.stats.refused;
    return false;
  }
  double peak = 0.0;
  {
    std::lock_guard lock(m.mutex);
    ++m.stats.scored;
    m.stats.last_percent = 100.0 * score.visible_share;
    m.stats.peak_force_n = std::max(m.stats.peak_force_n, m.tool_force_n);
    peak = m.stats.peak_force_n;
  }
  msg::GlotticView& s = m.sample;
  s.tool_body_id(m.tool_body_id);
  s.fem_step(m.fem_step);
  s.haptic_tick(m.haptic_tick);
  s.visible_percent(100.0 * score.visible_share);
  s.samples_facing(static_cast<std::uint32_t>(score.samples));
  s.samples_seen(static_cast<std::uint32_t>(score.visible));
  s.eye_m().x(eye.x());
  s.eye_m().y(eye.y());
  s.eye_m().z(eye.z());
  const Eigen::Vector3d& centre = m.view.view.opening().centre_m;
  s.opening_centre_m().x(centre.x());
  s.opening_centre_m().y(centre.y());
  s.opening_centre_m().z(centre.z());
  s.tool_force_n(m.tool_force_n);
  s.peak_tool_force_n(peak);
  s.header().sim_time_ns(m.sim_time_ns);
  s.header().sim_step(m.sim_step);
  if (m.publisher) {
    m.publisher->write(s);  // stamps seq, source time and writer id
  } else {
    s.header().seq(++m.seq);
    s.header().source_time_ns(common::wall_now_ns());
  }
  if (common::encode_cdr<msg::GlotticViewPubSubType>(s, m.bytes)) {
    m.live.put(kGlotticView, m.bytes, common::wall_now_ns());
  }
  return true;
}

GlotticViewService::Stats GlotticViewService::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace fahr::visualizer_service
