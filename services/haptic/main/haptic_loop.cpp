// The haptic tick (see haptic_loop.h).
#include "haptic_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "msg_conversion.h"

namespace fahr::haptic_service {
namespace {

// Tool contacts the query may report per tick. The blade pressing the
// tongue touches a few dozen of its finest spheres; candidates within the
// margin add as many again. 1024 leaves headroom, and a full buffer is
// counted, not fatal.
constexpr std::size_t kToolContactCapacity = 1024;
constexpr std::size_t kObstacleContactCapacity = 256;

template <class T>
void relaxed_store(std::atomic<T>& a, T v) {
  a.store(v, std::memory_order_relaxed);
}

double elapsed_us(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - since).count();
}

void store_max(std::atomic<double>& a, double v) {
  if (v > a.load(std::memory_order_relaxed)) a.store(v, std::memory_order_relaxed);
}

template <class T>
void relaxed_add(std::atomic<T>& a, T v) {
  a.fetch_add(v, std::memory_order_relaxed);
}

}  // namespace

HapticLoop::HapticLoop(const HapticSetup& setup)
    : setup_(setup),
      nominal_period_s_(1.0 / setup.scene->rates.haptic_hz),
      response_(setup.response),
      spheres_(setup.layout),
      tree_(setup.layout),
      positions_m_(3 * setup.mesh.node_count(), 0.0),
      tool_memory_(setup.layout.size()),
      tool_contacts_(kToolContactCapacity),
      order_(kToolContactCapacity, 0),
      rows_(setup.response.max_rows),
      obstacle_buffer_(kObstacleContactCapacity),
      obstacle_contacts_(kObstacleContactCapacity),
      obstacle_body_ids_(kObstacleContactCapacity, 0),
      compliance_index_(setup.layout.size(), contact::kNoCompliance),
      indexed_ids_(msg::MAX_COMPLIANCE_SPHERES, 0) {
  // Until the FEM publishes, the tongue is at rest: the tool can touch it
  // from the first tick (the response then uses the fallback compliance).
  spheres_.reset_to_rest(setup.layout);
  tree_.refit(spheres_);

  tool_body_.id = setup.tool->scene_body->id;
  tool_body_.sdf = setup.tool->sdf.get();
  // Spheres within 1 mm of the blade are sent as candidates, so the FEM
  // computes their compliance before they touch.
  tool_query_.candidate_margin_m = 1e-3;
  // The grid's distance (~0.1 us a sphere) rather than the triangles' (1-3
  // us on the 19k-triangle blade): with a few hundred spheres near the blade
  // the exact query alone can take the whole 1 ms period on a shared core.
  // It is exact on the blade's flat underside, off by a fraction of a cell
  // (0.5 mm) at its edges.
  tool_query_.exact_narrow_phase = false;

  // Tissue against anatomy changes only with the FEM state (200 Hz here), so
  // the grid distance is enough: off by a fraction of a cell at edges only.
  obstacle_query_.exact_narrow_phase = false;
  obstacle_query_.candidate_margin_m = 0.0;
  // The anatomy is thick: the field's normal points the right way even with
  // the centre inside, so no approach memory (which visits every sphere
  // within the margin: most of the tongue's underside lies 0.37 mm off the jaw).
  obstacle_query_.approach_margin_m = 0.0;
  for (const auto& field : setup.obstacles) {
    haptic::RigidBody body;
    body.id = field->scene_body->id;
    body.sdf = field->sdf.get();
    body.world_from_body = Eigen::Translation3d(field->scene_body->pose.position_m) * field->scene_body->pose.orientation;
    obstacle_bodies_.push_back(body);
    obstacle_memory_.emplace_back(setup.layout.size());
  }
  query_obstacles();
}

void HapticLoop::query_obstacles() {
  obstacle_buffer_.clear();
  for (std::size_t b = 0; b < obstacle_bodies_.size(); ++b) {
    const auto stats = haptic::query_spheres(tree_, spheres_, obstacle_bodies_[b], obstacle_query_,
                                             obstacle_memory_[b], obstacle_buffer_);
    if (stats.overflowed) relaxed_add<std::uint64_t>(metrics_.query_overflows, 1);
  }
  obstacle_count_ = 0;
  for (const haptic::SphereContact& s : obstacle_buffer_) {
    if (s.candidate || s.depth_m <= 0.0) continue;
    fem::Contact& c = obstacle_contacts_[obstacle_count_];
    c.sphere_id = s.sphere_id;
    c.kind = fem::ContactKind::kObstacle;
    c.state = fem::ContactState::kActive;
    c.plane_point_m = s.point_m;
    c.normal = s.normal;
    c.hold_centre_m = spheres_.centres_m()[s.sphere_id];
    c.penetration_m = s.depth_m;
    c.force_n = 0.0;  // a hard constraint: the FEM's projection alone resolves it
    obstacle_body_ids_[obstacle_count_] = s.body_id;
    ++obstacle_count_;
  }
  relaxed_store(metrics_.obstacle_contacts, static_cast<std::uint32_t>(obstacle_count_));
}

bool HapticLoop::take_state(const msg::DeformationState& state) {
  const auto start = std::chrono::steady_clock::now();
  const auto& x = state.positions_m();
  if (x.size() != positions_m_.size()) {
    relaxed_add<std::uint64_t>(metrics_.bad_states, 1);
    return false;
  }
  for (std::size_t i = 0; i < x.size(); ++i) positions_m_[i] = static_cast<double>(x[i]);
  if (!spheres_.update(setup_.layout, positions_m_)) {
    // A NaN from the FEM: the tree keeps the last good boxes; centres past
    // the bad node keep their last values.
    relaxed_add<std::uint64_t>(metrics_.bad_states, 1);
    return false;
  }
  tree_.refit(spheres_);
  query_obstacles();

  for (std::size_t i = 0; i < indexed_count_; ++i) compliance_index_[indexed_ids_[i]] = contact::kNoCompliance;
  indexed_count_ = 0;
  const auto& ids = state.compliance_sphere_ids();
  const std::size_t k = ids.size();
  const bool w_ok = state.compliance_mpn().size() >= 9 * k * k;
  if (w_ok) {
    for (std::size_t i = 0; i < k && i < indexed_ids_.size(); ++i) {
      if (ids[i] >= compliance_index_.size()) continue;
      compliance_index_[ids[i]] = static_cast<std::int32_t>(i);
      indexed_ids_[indexed_count_++] = ids[i];
    }
  }
  have_free_centres_ = w_ok && k > 0 && state.compliance_free_centres_m().size() >= 3 * k;
  relaxed_store(metrics_.free_centres, have_free_centres_);
  relaxed_add<std::uint64_t>(metrics_.fem_states, 1);
  const double state_us = elapsed_us(start);
  store_max(metrics_.state_us_max, state_us);
  store_max(metrics_.state_us_peak, state_us);
  return true;
}

contact::DeviceSample HapticLoop::device_sample(const msg::DevicePose& pose) {
  contact::DeviceSample d;
  d.pose_seq = pose.header().seq();
  d.position_m = to_eigen(pose.world_from_stylus().position_m());
  d.orientation = to_eigen(pose.world_from_stylus().orientation());
  d.velocity_mps = to_eigen(pose.linear_velocity_mps());
  d.renderable_force_n = std::max(0.0, pose.renderable_force_n());
  if (pose.max_stiffness_npm() > 0.0) d.max_stiffness_npm = pose.max_stiffness_npm();
  // The servo count gives the time since the last answered pose, whatever
  // DDS dropped in between; bounded so a stall does not make the damper vanish.
  const std::uint64_t ticks = started_ && pose.servo_tick() > last_servo_tick_ ? pose.servo_tick() - last_servo_tick_ : 1;
  d.dt_s = nominal_period_s_ * static_cast<double>(std::min<std::uint64_t>(ticks, 10));
  last_servo_tick_ = pose.servo_tick();
  return d;
}

void HapticLoop::collect_rows(const msg::DeformationState* state) {
  const std::size_t n = tool_contacts_.size();
  std::iota(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(n), 0u);
  const std::size_t keep = std::min(n, rows_.size());
  if (n > keep) {
    // More than W can cover: keep the deepest (touching before candidates).
    std::partial_sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(keep),
                      order_.begin() + static_cast<std::ptrdiff_t>(n), [&](std::uint32_t a, std::uint32_t b) {
                        return tool_contacts_[a].depth_m > tool_contacts_[b].depth_m;
                      });
    relaxed_add<std::uint64_t>(metrics_.rows_dropped, n - keep);
  }
  const float* free_centres = have_free_centres_ && state != nullptr ? state->compliance_free_centres_m().data() : nullptr;
  for (std::size_t r = 0; r < keep; ++r) {
    const haptic::SphereContact& s = tool_contacts_[order_[r]];
    contact::ContactRow& row = rows_[r];
    row.kind = contact::RowKind::kTissue;
    row.id = s.sphere_id;
    row.normal = s.normal;
    row.tool_point_m = s.point_m;
    row.radius_m = spheres_.radii_m()[s.sphere_id];
    row.compliance_index = state != nullptr ? compliance_index_[s.sphere_id] : contact::kNoCompliance;
    row.other_point_m = spheres_.centres_m()[s.sphere_id];
    if (free_centres != nullptr && row.compliance_index >= 0) {
      // Penetration on the free-motion centre (services/contact README,
      // "Which centre"): the projected one reads zero at a steady contact.
      const float* c = free_centres + 3 * row.compliance_index;
      row.other_point_m = Eigen::Vector3d(c[0], c[1], c[2]);
    }
  }
  row_count_ = keep;
}

void HapticLoop::tick(const msg::DevicePose& pose, const msg::DeformationState* state, msg::ForceCommand& command,
                      msg::ContactSet& contacts) {
  const auto start = std::chrono::steady_clock::now();
  const contact::DeviceSample device = device_sample(pose);
  if (!started_) {
    response_.reset(device.position_m, device.orientation);
    started_ = true;
  }
  // Rows are measured with the tool at the proxy, in the device's
  // orientation: the reference pose p0 of the solve.
  tool_body_.world_from_body = Eigen::Translation3d(response_.proxy().position_m) * device.orientation;
  tool_contacts_.clear();
  const auto stats = haptic::query_spheres(tree_, spheres_, tool_body_, tool_query_, tool_memory_, tool_contacts_);
  if (stats.overflowed) relaxed_add<std::uint64_t>(metrics_.query_overflows, 1);
  collect_rows(state);

  contact::TickInput input;
  input.device = device;
  input.rows = {rows_.data(), row_count_};
  if (state != nullptr) {
    input.compliance.fem_step = state->step();
    if (indexed_count_ > 0) {
      input.compliance.sphere_ids = {state->compliance_sphere_ids().data(), state->compliance_sphere_ids().size()};
      input.compliance.w_mpn = {state->compliance_mpn().data(), state->compliance_mpn().size()};
    }
  }
  input.tissue_obstacle_contacts = {obstacle_contacts_.data(), obstacle_count_};
  const contact::ForceOutput& out = response_.tick(input);
  const double solve_us = elapsed_us(start);
  store_max(metrics_.solve_us_max, solve_us);
  store_max(metrics_.solve_us_peak, solve_us);

  fill_command(out, pose.device_id(), command);
  command.header().sim_step(pose.servo_tick());
  command.header().sim_time_ns(pose.header().sim_time_ns());
  contacts.body_id(setup_.deformable->id);
  contacts.haptic_tick(tick_);
  contacts.fem_step(state != nullptr ? state->step() : 0);
  contacts.tool_frozen(response_.tool_frozen());
  fill_contacts(response_.contacts(), tool_body_.id, {obstacle_body_ids_.data(), obstacle_count_}, contacts);
  contacts.header().sim_step(pose.servo_tick());
  contacts.header().sim_time_ns(pose.header().sim_time_ns());
  ++tick_;

  relaxed_add<std::uint64_t>(metrics_.ticks, 1);
  relaxed_store(metrics_.tool_rows, static_cast<std::uint32_t>(row_count_));
  relaxed_store(metrics_.active_contacts, out.active_contacts);
  relaxed_store(metrics_.missing_compliance,
                static_cast<std::uint32_t>(std::max(0, response_.report().load.missing_compliance)));
  relaxed_store(metrics_.reaction_n, out.tissue_reaction_n);
  const double force_n = out.force_n.norm();
  if (force_n > metrics_.peak_force_n.load(std::memory_order_relaxed)) relaxed_store(metrics_.peak_force_n, force_n);
  if (out.lost_track) {
    relaxed_add<std::uint64_t>(metrics_.lost_track_ticks, 1);
    if (!was_lost_) relaxed_add<std::uint64_t>(metrics_.lost_track_episodes, 1);
  }
  was_lost_ = out.lost_track;
}

void HapticLoop::append_metrics(std::vector<std::pair<std::string, double>>& out) {
  const auto get = [](const auto& a) { return static_cast<double>(a.load(std::memory_order_relaxed)); };
  out.emplace_back("fem_states", get(metrics_.fem_states));
  out.emplace_back("bad_states", get(metrics_.bad_states));
  out.emplace_back("tool_rows", get(metrics_.tool_rows));
  out.emplace_back("active_contacts", get(metrics_.active_contacts));
  out.emplace_back("obstacle_contacts", get(metrics_.obstacle_contacts));
  out.emplace_back("rows_dropped", get(metrics_.rows_dropped));
  out.emplace_back("query_overflows", get(metrics_.query_overflows));
  out.emplace_back("missing_compliance", get(metrics_.missing_compliance));
  out.emplace_back("lost_track_ticks", get(metrics_.lost_track_ticks));
  out.emplace_back("lost_track_episodes", get(metrics_.lost_track_episodes));
  out.emplace_back("free_centres", metrics_.free_centres.load(std::memory_order_relaxed) ? 1.0 : 0.0);
  out.emplace_back("tissue_reaction_n", get(metrics_.reaction_n));
  out.emplace_back("peak_force_n", get(metrics_.peak_force_n));
  out.emplace_back("spheres", static_cast<double>(setup_.layout.size()));
  out.emplace_back("state_us_max", metrics_.state_us_max.exchange(0.0, std::memory_order_relaxed));
  out.emplace_back("solve_us_max", metrics_.solve_us_max.exchange(0.0, std::memory_order_relaxed));
}

}  // namespace fahr::haptic_service
