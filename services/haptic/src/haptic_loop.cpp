// The haptic tick (see haptic_loop.h).
#include "fahr/haptic_service/haptic_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "fahr/common/wire_eigen.h"
#include "fahr/haptic_service/msg_conversion.h"

namespace fahr::haptic_service {
namespace {

// Tool contacts the query may report per tick. The blade pressing the
// tongue touches a few dozen of its finest spheres; candidates within the
// margin add as many again. 1024 leaves headroom, and a full buffer is
// counted, not fatal.
constexpr std::size_t kToolContactCapacity = 1024;
// Tool surface samples near the anatomy in one tick (1.5 mm apart): the
// blade lying along the palate brings a few hundred within the margin.
constexpr std::size_t kAnatomyContactCapacity = 512;
// Tool samples within this distance of the anatomy become rows (separated,
// lambda = 0 unless the proxy moves into them): the solve then stops the
// proxy within the tick instead of one tick late, m. 1 mm: a hand at 1 m/s.
constexpr double kAnatomyMarginM = 1e-3;

template <class T>
void relaxed_store(std::atomic<T>& a, T v) {
  a.store(v, std::memory_order_relaxed);
}

double elapsed_us(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - since)
      .count();
}

void store_max(std::atomic<double>& a, double v) {
  if (v > a.load(std::memory_order_relaxed)) a.store(v, std::memory_order_relaxed);
}

template <class T>
void relaxed_add(std::atomic<T>& a, T v) {
  a.fetch_add(v, std::memory_order_relaxed);
}

// Puts the `keep` deepest of indices[0, n) first (indices into `contacts`,
// each with a depth_m) when there are more than that; returns how many were
// dropped. In place, allocation-free.
template <class Contact>
std::size_t keep_deepest(std::vector<std::uint32_t>& indices, std::size_t n, std::size_t keep,
                         const Contact& contacts) {
  if (n <= keep) return 0;
  std::partial_sort(
      indices.begin(), indices.begin() + static_cast<std::ptrdiff_t>(keep),
      indices.begin() + static_cast<std::ptrdiff_t>(n),
      [&](std::uint32_t a, std::uint32_t b) { return contacts[a].depth_m > contacts[b].depth_m; });
  return n - keep;
}

}  // namespace

std::string w_summary(const LoopMetrics& m) {
  const auto get = [](const std::atomic<std::uint64_t>& a) {
    return static_cast<unsigned long long>(a.load(std::memory_order_relaxed));
  };
  char line[320];
  std::snprintf(line, sizeof line,
                "ticks with an indefinite W made semidefinite %llu (largest diagonal scale %.3f), "
                "coupled steps refused %llu; rows without W %llu",
                get(m.indefinite_w_ticks), m.w_diagonal_scale_max.load(std::memory_order_relaxed),
                get(m.refused_steps), get(m.rows_without_compliance));
  return line;
}

void split_contacts(const HapticSetup& setup, const TissueSnapshot& tissue,
                    const msg::ContactSet& joined, std::span<msg::ContactSet* const> out) {
  for (std::size_t b = 0; b < out.size(); ++b) {
    msg::ContactSet& set = *out[b];
    const TissueBody& body = setup.bodies[b];
    set.header(joined.header());
    set.body_id(body.body->id);
    set.haptic_tick(joined.haptic_tick());
    set.fem_step(tissue.from_fem ? tissue.body_fem_steps[b] : joined.fem_step());
    set.layout_fingerprint(body.layout_fingerprint);
    set.tool_frozen(joined.tool_frozen());
    set.world_from_tool(joined.world_from_tool());
    set.contacts().clear();
  }
  for (const msg::Contact& c : joined.contacts()) {
    const std::size_t b = body_of_sphere(setup, c.sphere_id());
    msg::ContactSet& set = *out[b];
    if (set.contacts().size() == msg::MAX_CONTACTS) continue;
    set.contacts().push_back(c);
    set.contacts().back().sphere_id(c.sphere_id() - setup.bodies[b].first_sphere);
  }
}

HapticLoop::HapticLoop(const HapticSetup& setup)
    : setup_(setup),
      layout_fingerprint_(setup.bodies.front().layout_fingerprint),
      nominal_period_s_(1.0 / setup.scene->rates.haptic_hz),
      response_(setup.response),
      penalty_(setup.penalty_settings),
      penalty_contacts_(setup.response.max_contacts),
      tool_memory_(setup.layout.size()),
      tool_contacts_(kToolContactCapacity),
      order_(kToolContactCapacity, 0),
      row_key_(kToolContactCapacity, 0.0),
      order_scratch_(setup.bodies.size() * msg::MAX_COMPLIANCE_SPHERES, 0),
      free_depth_m_(setup.bodies.size() * msg::MAX_COMPLIANCE_SPHERES, 0.0),
      request_of_(msg::MAX_COMPLIANCE_SPHERES, 0),
      requests_(msg::MAX_COMPLIANCE_SPHERES),
      anatomy_contacts_(kAnatomyContactCapacity),
      anatomy_order_(kAnatomyContactCapacity, 0),
      compliance_block_(std::min<std::size_t>(
          static_cast<std::size_t>(std::max(0, setup.scene->solver.max_candidate_contacts)),
          msg::MAX_COMPLIANCE_SPHERES)),
      tissue_row_budget_(std::min<std::size_t>(
          compliance_block_ - std::min(kComplianceLookAhead, compliance_block_ / 3),
          setup.response.max_rows)),
      row_margin_m_(std::clamp(setup.row_margin_m, 0.0, setup.candidate_margin_m)),
      rows_(setup.response.max_rows) {
  if (setup.collision == CollisionMethod::kTriangle) {
    triangle_contacts_.reserve(kToolContactCapacity);
    row_of_sphere_.assign(setup.layout.size(), -1);
    sphere_contact_.assign(kToolContactCapacity, 0);
    slot_sphere_.assign(kToolContactCapacity, 0);
  }
  // Each body's load is bounded by what the device renders, not only their
  // sum (a blade between the tongue and the epiglottis).
  std::vector<std::uint32_t> first_spheres;
  for (const TissueBody& body : setup.bodies) first_spheres.push_back(body.first_sphere);
  response_.set_tissue_bodies(first_spheres);
  tool_body_.id = setup.tool->scene_body->id;
  tool_body_.sdf = setup.tool->sdf.get();
  tool_body_.grid = setup.tool_grid.get();
  // Spheres near the blade are sent as candidates, so the FEM computes
  // their compliance before they touch.
  tool_query_.candidate_margin_m = setup.candidate_margin_m;
  // The grid's distance (~0.1 us a sphere) rather than the triangles' (1-3
  // us on the 19k-triangle blade): with a few hundred spheres near the blade
  // the exact query alone can take the whole 1 ms period on a shared core.
  // It is exact on the blade's flat underside, off by a fraction of a cell
  // (0.5 mm) at its edges.
  tool_query_.exact_narrow_phase = false;
  // The rows take the contact point, normal and depth only: no surface point
  // (a face read and a closest point per reported sphere, ~500 a pressed tick).
  tool_query_.surface_probe = collision::QuerySettings::SurfaceProbe::kNone;
  // Of ~540 contacts a pressed tick ~64 become rows: the others' normals
  // (a gradient, a square root, two transforms each) are not worked out.
  tool_query_.defer_outside_contacts = true;
  for (const std::size_t a : setup.tool_obstacles) {
    const RigidField& field = *setup.anatomy[a];
    collision::RigidBody body;
    body.id = field.scene_body->id;
    body.sdf = field.sdf.get();
    body.world_from_body = Eigen::Translation3d(field.scene_body->pose.position_m) *
                           field.scene_body->pose.orientation;
    anatomy_bodies_.push_back(body);
  }
}

contact::DeviceSample HapticLoop::device_sample(const msg::DevicePose& pose) {
  contact::DeviceSample d;
  d.pose_seq = pose.header().seq();
  d.position_m = common::to_eigen(pose.world_from_stylus().position_m());
  d.orientation = common::to_unit_quaternion(pose.world_from_stylus().orientation());
  d.velocity_mps = common::to_eigen(pose.linear_velocity_mps());
  d.renderable_force_n = std::max(0.0, pose.renderable_force_n());
  if (pose.max_stiffness_npm() > 0.0) d.max_stiffness_npm = pose.max_stiffness_npm();
  // The servo count gives the time since the last answered pose, whatever
  // DDS dropped in between; bounded so a stall does not make the damper vanish.
  const std::uint64_t ticks =
      started_ && pose.servo_tick() > last_servo_tick_ ? pose.servo_tick() - last_servo_tick_ : 1;
  d.dt_s = nominal_period_s_ * static_cast<double>(std::min<std::uint64_t>(ticks, 10));
  last_servo_tick_ = pose.servo_tick();
  return d;
}

// The rows: every contact within the row margin whose sphere has W in this
// state (the FEM's block, compliance_block_ spheres), the deepest first, at
// most the row budget. No constant stands in for the tissue: a contact
// without W is never a row. Those among the budget's deepest contacts are
// counted (rows without tissue compliance). Contacts between the row margin
// and the candidate margin are never rows; they are the look-ahead from
// which the block's free slots are filled, so a sphere has its W by the
// time it enters the row margin.
//
// Depth is the one the solve uses: a W sphere's on its free-motion centre
// when the FEM sent them (collect_tissue_rows), the others' on their
// published centres, which the FEM did not project. A W sphere's published
// depth reads about zero after the FEM's projection; ranked by it, every
// row of the last ContactSet looked shallower than the unprojected contacts
// beside it, those were counted as rows without W although the solve's rows
// were deeper, and 362 solves in the 20 s intubation ran to the sweep cap
// against 21 (docs/design/compliance-block.md). A W sphere's free depth is
// taken once per FEM state, at the tool's pose on its first tick: taken on
// every tick, the rows at the budget's edge changed with the proxy's motion
// of the tick before, and on one state the force alternated by 0.08 N from
// one tick to the next.
//
// The block's other slots go to the deepest of the remaining contacts, with
// W or without (requests: candidates in the next ContactSet), so the FEM's
// next block is the block's worth of contacts nearest to being rows. A
// sphere keeps its W while it stays among them; it is dropped only for a
// deeper one. Asking for the deepest contacts without W alone replaced the
// look-ahead's spheres with new ones at every FEM step although they were
// no deeper: in the 20 s intubation the FEM solved 28 % more new columns and
// 1.8 times as many contacts were deep enough to be rows without having W
// (docs/design/compliance-block.md).
//
// A W sphere is a row whatever the depth of contacts without W around it.
// Ranked among all contacts, the W spheres (projected onto the blade by the
// FEM, so shallower than the unprojected spheres between them) fell in and
// out of the deepest ranks as the proxy moved a fraction of a millimetre,
// and on one FEM state the row set, and the force, alternated from one tick
// to the next (12 rows and 1.14 N, 8 rows and 0.61 N, a real-time trace on
// a 2-core station).
//
// order_ ends with the rows first, then the requests; allocation-free.
void HapticLoop::select_rows(const TissueSnapshot& tissue) {
  const std::size_t n = std::min(tool_contacts_.size(), order_.size());
  std::size_t with_w = 0;
  std::size_t without_w = 0;
  // A W sphere's key is its free-motion depth at the tool's pose on the
  // first tick of its FEM state: the depth its row is solved at, fixed while
  // the state is (the penalty baseline reads the published centres).
  const bool free_depth = tissue.from_fem && tissue.have_free_centres && !setup_.penalty;
  if (free_depth &&
      (!free_depth_valid_ || free_depth_step_ != tissue.fem_step ||
       free_depth_writer_ != tissue.fem_writer || free_depth_epoch_ != tissue.reset_epoch)) {
    const Eigen::Isometry3d tool_from_world = tool_body_.world_from_body.inverse();
    for (std::size_t w = 0; w < tissue.compliance_count; ++w) {
      // As the query measures a sphere: radius plus skin less the distance.
      const float* f = tissue.free_centres_m.data() + 3 * static_cast<std::ptrdiff_t>(w);
      const Eigen::Vector3d c = tool_from_world * Eigen::Vector3d(f[0], f[1], f[2]);
      const double d = tool_body_.grid != nullptr ? tool_body_.grid->distance(c)
                                                  : tool_body_.sdf->grid_distance(c);
      free_depth_m_[w] =
          tissue.spheres.radii_m()[tissue.compliance_ids[w]] + tool_query_.contact_skin_m - d;
    }
    free_depth_step_ = tissue.fem_step;
    free_depth_writer_ = tissue.fem_writer;
    free_depth_epoch_ = tissue.reset_epoch;
    free_depth_valid_ = true;
  }
  // Only contacts within the row margin are rows; the rest of the candidate
  // margin is the W look-ahead.
  const double row_floor = -row_margin_m_;
  const auto in_row_band = [&](std::uint32_t i) { return row_key_[i] > row_floor; };
  std::size_t in_band = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const collision::SphereContact& s = tool_contacts_[i];
    const std::int32_t w = tissue.compliance_index[s.sphere_id];
    const double key =
        w >= 0 && free_depth ? free_depth_m_[static_cast<std::size_t>(w)] : s.depth_m;
    row_key_[i] = key;
    in_band += key > row_floor ? 1 : 0;
    if (w >= 0 && with_w < order_scratch_.size()) {
      order_scratch_[with_w++] = i;
    } else {
      order_[without_w++] = i;
    }
  }
  const auto deeper = [&](std::uint32_t a, std::uint32_t b) { return row_key_[a] > row_key_[b]; };
  // The W spheres (at most the block, so all of them), deepest first: the
  // rows, then the deepest W spheres that are not rows.
  std::sort(order_scratch_.begin(), order_scratch_.begin() + static_cast<std::ptrdiff_t>(with_w),
            deeper);
  row_pick_ = 0;
  while (row_pick_ < std::min(with_w, tissue_row_budget_) &&
         in_row_band(order_scratch_[row_pick_])) {
    ++row_pick_;
  }
  const std::size_t others_wanted = compliance_block_ - row_pick_;
  const auto kept_begin = order_scratch_.begin() + static_cast<std::ptrdiff_t>(row_pick_);
  const std::size_t kept = std::min(with_w - row_pick_, others_wanted);
  // The deepest contacts without W, as far as either use needs them.
  const auto without_w_end = order_.begin() + static_cast<std::ptrdiff_t>(without_w);
  const std::size_t sorted = std::min(without_w, std::max(tissue_row_budget_, others_wanted));
  std::partial_sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(sorted),
                    without_w_end, deeper);
  // Rows without W: contacts without W within the row margin and deeper
  // than the budget-th deepest contact of all (what a ranking by depth alone
  // would have made rows).
  std::size_t row_ranked = 0;
  while (row_ranked < std::min(sorted, tissue_row_budget_) && in_row_band(order_[row_ranked]))
    ++row_ranked;
  std::size_t deep_without_w = 0;
  std::size_t touching = 0;
  if (n <= tissue_row_budget_) {
    deep_without_w = row_ranked;
    for (std::size_t k = 0; k < row_ranked; ++k) touching += row_key_[order_[k]] > 0.0 ? 1 : 0;
  } else {
    // Merge the two descending heads (each sorted as far as the budget)
    // for the budget deepest contacts.
    std::size_t a = 0;
    std::size_t b = 0;
    for (std::size_t taken = 0; taken < tissue_row_budget_ && (a < row_pick_ || b < row_ranked);
         ++taken) {
      if (a < row_pick_ &&
          (b >= row_ranked || row_key_[order_scratch_[a]] >= row_key_[order_[b]])) {
        ++a;
      } else {
        touching += row_key_[order_[b]] > 0.0 ? 1 : 0;
        ++b;
        ++deep_without_w;
      }
    }
  }
  // The block's other slots: the kept W spheres and the contacts without W,
  // merged deepest first.
  std::size_t a = 0;
  std::size_t b = 0;
  request_count_ = 0;
  while (request_count_ < others_wanted && (a < kept || b < sorted)) {
    const bool take_kept =
        a < kept && (b >= sorted ||
                     row_key_[kept_begin[static_cast<std::ptrdiff_t>(a)]] >= row_key_[order_[b]]);
    request_of_[request_count_++] =
        take_kept ? kept_begin[static_cast<std::ptrdiff_t>(a++)] : order_[b++];
  }
  std::copy_n(order_scratch_.begin(), row_pick_, order_.begin());
  std::copy_n(request_of_.begin(), request_count_,
              order_.begin() + static_cast<std::ptrdiff_t>(row_pick_));
  // Dropped: contacts within the row margin that are not rows (the look-ahead
  // band's are not rows by design).
  relaxed_add<std::uint64_t>(metrics_.rows_dropped, in_band - row_pick_);
  rows_without_w_ = deep_without_w;
  touching_without_w_ = touching;
}

// The ContactSet's tool contacts: the last response's (the penalty
// baseline's), then `requests`, then the tissue's obstacle contacts.
void HapticLoop::fill_tool_contacts(std::span<const fem::Contact> requests,
                                    const TissueSnapshot& tissue, msg::ContactSet& contacts) const {
  if (setup_.penalty) {
    contacts.tool_frozen(false);
    fill_contacts({penalty_contacts_.data(), penalty_count_}, requests, tool_body_.id,
                  tissue.tissue_obstacle_body_ids(), contacts);
  } else {
    contacts.tool_frozen(response_.tool_frozen());
    fill_contacts(response_.contacts(), requests, tool_body_.id, tissue.tissue_obstacle_body_ids(),
                  contacts);
  }
}

// A request for a sphere's W: a candidate contact, projected by nobody.
static fem::Contact compliance_request(std::uint32_t sphere, const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& point_m, double depth_m,
                                       const TissueSnapshot& tissue) {
  fem::Contact c;
  c.sphere_id = sphere;
  c.kind = fem::ContactKind::kTool;
  c.state = fem::ContactState::kCandidate;
  c.normal = normal;
  c.plane_point_m = point_m;
  c.hold_centre_m = tissue.spheres.centres_m()[sphere];
  c.penetration_m = depth_m;
  c.force_n = 0.0;
  return c;
}

void HapticLoop::collect_tissue_rows(const TissueSnapshot& tissue) {
  select_rows(tissue);
  // Only the rows and the requests get their point and normal
  // (defer_outside_contacts).
  collision::complete_deferred(tissue.tree, tool_body_, tool_query_, tool_contacts_, order_.data(),
                               row_pick_ + request_count_);
  for (std::size_t q = 0; q < request_count_; ++q) {
    const collision::SphereContact& s = tool_contacts_[order_[row_pick_ + q]];
    requests_[q] = compliance_request(s.sphere_id, s.normal, s.point_m, s.depth_m, tissue);
  }
  // (The penalty baseline's forces are part of the FEM's step, so it reads
  // the published centres.)
  const bool free_centres = tissue.from_fem && tissue.have_free_centres && !setup_.penalty;
  for (std::size_t r = 0; r < row_pick_; ++r) {
    const collision::SphereContact& s = tool_contacts_[order_[r]];
    contact::ContactRow& row = rows_[row_count_++];
    row.kind = contact::RowKind::kTissue;
    row.id = s.sphere_id;
    row.normal = s.normal;
    row.tool_point_m = s.point_m;
    row.radius_m = tissue.spheres.radii_m()[s.sphere_id];
    row.compliance_index = tissue.compliance_index[s.sphere_id];
    row.other_point_m = tissue.spheres.centres_m()[s.sphere_id];
    if (free_centres && row.compliance_index >= 0) {
      // Penetration on the free-motion centre (which centre:
      // docs/design/contact-contract.md): the projected one reads zero at a
      // steady contact.
      const float* c =
          tissue.free_centres_m.data() + 3 * static_cast<std::ptrdiff_t>(row.compliance_index);
      row.other_point_m = Eigen::Vector3d(c[0], c[1], c[2]);
    }
  }
}

// The baseline's vertex-face contacts as rows of the same response: each
// tongue vertex behind a blade face (or within the candidate margin in front
// of it: a candidate row, as the AIST's) speaks for the sphere nearest it at
// rest (its compliance, its ContactSet entry); the deepest contact per sphere
// is kept. The vertex comes from the published (projected) positions; it is
// moved by its sphere's free-motion offset, as the AIST rows use the free
// centres. Blade vertices behind a tongue face (the tip's edge) are found,
// and timed, but give no row: as rows on the face's nearest corner sphere
// they drove the intubation's tongue to thousands of inverted tets within
// 20 s (fahr_stack_sim_run --collision triangle), since the FEM projects that
// sphere, radius included, onto the plane through a blade vertex.
void HapticLoop::collect_triangle_rows(const TissueSnapshot& tissue) {
  // The AIST rows' row margin: both methods hand the solve the same kind of rows.
  tissue.triangles->collide(tool_body_.world_from_body, triangle_contacts_, row_margin_m_);
  const auto& vertex_sphere = setup_.triangles->vertex_sphere;
  std::size_t slots = 0;
  for (std::size_t i = 0; i < triangle_contacts_.size() && slots < sphere_contact_.size(); ++i) {
    const collision::TriangleContact& c = triangle_contacts_[i];
    if (c.tissue_vertex < 0) continue;
    const std::uint32_t sphere = vertex_sphere[static_cast<std::size_t>(c.tissue_vertex)];
    const std::int32_t slot = row_of_sphere_[sphere];
    if (slot < 0) {
      row_of_sphere_[sphere] = static_cast<std::int32_t>(slots);
      slot_sphere_[slots] = sphere;
      sphere_contact_[slots++] = static_cast<std::uint32_t>(i);
    } else if (c.depth_m >
               triangle_contacts_[sphere_contact_[static_cast<std::size_t>(slot)]].depth_m) {
      sphere_contact_[static_cast<std::size_t>(slot)] = static_cast<std::uint32_t>(i);
    }
  }
  for (std::size_t k = 0; k < slots; ++k) row_of_sphere_[slot_sphere_[k]] = -1;
  const std::size_t keep = std::min(slots, tissue_row_budget_);
  relaxed_add<std::uint64_t>(metrics_.rows_dropped,
                             keep_deepest(sphere_contact_, slots, keep, triangle_contacts_));
  // (The penalty baseline's forces are part of the FEM's step, so it reads
  // the published centres.)
  const bool free_centres = tissue.from_fem && tissue.have_free_centres && !setup_.penalty;
  for (std::size_t r = 0; r < keep; ++r) {
    const collision::TriangleContact& c = triangle_contacts_[sphere_contact_[r]];
    const std::uint32_t sphere = vertex_sphere[static_cast<std::size_t>(c.tissue_vertex)];
    contact::ContactRow& row = rows_[row_count_++];
    row.kind = contact::RowKind::kTissue;
    row.id = sphere;
    row.normal = c.normal;
    row.tool_point_m = c.point_m;
    row.other_point_m = c.point_m - c.depth_m * c.normal;  // the vertex: depth = -(v - q) . n
    row.radius_m = 0.0;
    row.compliance_index = tissue.compliance_index[sphere];
    if (free_centres && row.compliance_index >= 0) {
      const float* f =
          tissue.free_centres_m.data() + 3 * static_cast<std::ptrdiff_t>(row.compliance_index);
      row.other_point_m += Eigen::Vector3d(f[0], f[1], f[2]) - tissue.spheres.centres_m()[sphere];
    }
    if (row.compliance_index < 0) {
      // No W yet: counted, and asked for as the AIST rows' are (deepest
      // first), or the baseline's rows would never get any and render
      // nothing.
      ++rows_without_w_;
      if (c.depth_m > 0.0) ++touching_without_w_;
      if (request_count_ < compliance_block_ - keep)
        requests_[request_count_++] =
            compliance_request(sphere, c.normal, c.point_m, c.depth_m, tissue);
    }
  }
}

void HapticLoop::collect_anatomy_rows(const Eigen::Isometry3d& world_from_tool) {
  std::size_t n = 0;
  for (const collision::RigidBody& body : anatomy_bodies_) {
    const auto stats = collision::query_surface_samples(setup_.tool_samples, world_from_tool, body,
                                                        kAnatomyMarginM, anatomy_contacts_, n);
    if (stats.overflowed) relaxed_add<std::uint64_t>(metrics_.query_overflows, 1);
  }
  const std::size_t keep = std::min({n, kMaxAnatomyRows, rows_.size() - row_count_});
  std::iota(anatomy_order_.begin(), anatomy_order_.begin() + static_cast<std::ptrdiff_t>(n), 0u);
  relaxed_add<std::uint64_t>(metrics_.rows_dropped,
                             keep_deepest(anatomy_order_, n, keep, anatomy_contacts_));
  for (std::size_t r = 0; r < keep; ++r) {
    const collision::SurfaceContact& c = anatomy_contacts_[anatomy_order_[r]];
    contact::ContactRow& row = rows_[row_count_++];
    row.kind = contact::RowKind::kObstacle;
    // (body, sample) keys the warm start: body ids are small scene indices,
    // samples fewer than 2^20.
    row.id = (c.body_id << 20) | c.sample;
    // From the tool toward the anatomy: moving the tool into it deepens the row.
    row.normal = -c.normal;
    row.tool_point_m = c.tool_point_m;
    row.other_point_m = c.surface_point_m;
    row.radius_m = 0.0;
    row.compliance_index = contact::kNoCompliance;
  }
  relaxed_store(metrics_.anatomy_rows, static_cast<std::uint32_t>(keep));
}

void HapticLoop::begin_resume(const contact::DeviceSample& device) {
  response_.reset(device.position_m, device.orientation);
  slewing_ = true;
  slew_ticks_left_ = kSlewWindowTicks;
}

void HapticLoop::tick(const msg::DevicePose& pose, const TissueSnapshot& tissue,
                      msg::ForceCommand& command, msg::ContactSet& contacts, bool tissue_lost) {
  const auto start = std::chrono::steady_clock::now();
  const contact::DeviceSample device = device_sample(pose);
  if (!started_) {
    response_.reset(device.position_m, device.orientation);
    started_ = true;
  }
  // The device renders nothing (disabled, engaging, faulted) or ramps our
  // last force down (commands went silent): the force we send next starts
  // from what it renders, not from what we sent.
  const msg::DeviceSafetyState device_state = pose.safety_state();
  const bool device_idle =
      device_state != msg::DEVICE_FORCE_ENABLED && device_state != msg::DEVICE_RAMPING_DOWN;
  if (device_idle || device_state == msg::DEVICE_RAMPING_DOWN) {
    rendered_n_ = common::to_eigen(pose.rendered_force_n());
    slewing_ = true;
    slew_ticks_left_ = kSlewWindowTicks;
  }
  device_idle_ = device_idle;
  if (tissue_lost) {
    lost_tick(pose, device, tissue, command, contacts);
    const double tick_us = elapsed_us(start);
    store_max(metrics_.tick_us_max, tick_us);
    store_max(metrics_.tick_us_peak, tick_us);
    return;
  }
  if (tissue_lost_) {
    // A state came again: the force slews from the ramp's value. The same
    // FEM after a stall has the tongue where it left it (relaxed, if
    // anything: the ContactSets were empty), so the proxy stays where that
    // tongue held it and goes on from there; a new writer or a new epoch
    // (below) moves it to the hand.
    tissue_lost_ = false;
    slewing_ = true;
    slew_ticks_left_ = kSlewWindowTicks;
    relaxed_add<std::uint64_t>(metrics_.tissue_returns, 1);
  }
  if (tissue.from_fem && tissue.fem_writer != fem_writer_) {
    // A restarted FEM service (a new writer) starts from rest with its own
    // step and epoch numbering: the same resume as a reset epoch.
    if (fem_writer_ != 0) {
      begin_resume(device);
      relaxed_add<std::uint64_t>(metrics_.fem_writers, 1);
    }
    fem_writer_ = tissue.fem_writer;
    reset_epoch_ = tissue.reset_epoch;
  }
  if (tissue.from_fem && tissue.reset_epoch != reset_epoch_) {
    // The tongue jumped back to rest: what the proxy held and the contacts
    // it had mean nothing now. The proxy goes to the hand, and the force
    // slews from what was rendered to what the new tongue gives.
    reset_epoch_ = tissue.reset_epoch;
    begin_resume(device);
    relaxed_add<std::uint64_t>(metrics_.tissue_resets, 1);
  }
  if (tissue.from_fem && tissue.fem_step != last_fem_step_) {
    last_fem_step_ = tissue.fem_step;
    relaxed_add<std::uint64_t>(metrics_.snapshots, 1);
  }
  // Rows are measured with the tool at the proxy, in the device's
  // orientation: the reference pose p0 of the solve. The penalty baseline
  // has no proxy: its tool is the device.
  const Eigen::Vector3d tool_at = setup_.penalty ? device.position_m : response_.proxy().position_m;
  tool_body_.world_from_body = Eigen::Translation3d(tool_at) * device.orientation;
  row_count_ = 0;
  request_count_ = 0;
  rows_without_w_ = 0;
  touching_without_w_ = 0;
  const auto query_start = std::chrono::steady_clock::now();
  phases_.tissue_query = {};
  if (setup_.collision == CollisionMethod::kTriangle && tissue.triangles) {
    collect_triangle_rows(tissue);
  } else {
    tool_contacts_.clear();
    const auto stats = collision::query_spheres(tissue.tree, tissue.spheres, tool_body_,
                                                tool_query_, tool_memory_, tool_contacts_);
    if (stats.overflowed) relaxed_add<std::uint64_t>(metrics_.query_overflows, 1);
    phases_.tissue_query = stats;
    collect_tissue_rows(tissue);
  }
  const std::size_t tissue_rows = row_count_;
  const auto anatomy_start = std::chrono::steady_clock::now();
  collect_anatomy_rows(tool_body_.world_from_body);
  const auto response_start = std::chrono::steady_clock::now();

  const contact::ForceOutput* output = nullptr;
  if (setup_.penalty) {
    output = &penalty_tick(device, tissue);
  } else {
    contact::TickInput input;
    input.device = device;
    input.rows = {rows_.data(), row_count_};
    if (tissue.from_fem) input.compliance = tissue.compliance();
    input.tissue_obstacle_contacts = tissue.tissue_obstacle_contacts();
    output = &response_.tick(input);
  }
  const contact::ForceOutput& out = *output;
  const auto response_end = std::chrono::steady_clock::now();
  using Micro = std::chrono::duration<double, std::micro>;
  phases_.tissue_query_us = Micro(anatomy_start - query_start).count();
  phases_.anatomy_query_us = Micro(response_start - anatomy_start).count();
  phases_.response_us = Micro(response_end - response_start).count();

  fill_command(out, pose.device_id(), command);
  command.reason(msg::FORCE_RENDERED);
  if (device_idle) {
    // Zero until the device has engaged (its engage rule wants a small
    // force), then the slew from zero.
    common::put(Eigen::Vector3d(Eigen::Vector3d::Zero()), command.force_n());
    common::put(Eigen::Matrix3d(Eigen::Matrix3d::Zero()), command.stiffness_npm());
    command.reason(msg::FORCE_DEVICE_NOT_ENABLED);
    relaxed_add<std::uint64_t>(metrics_.device_idle_ticks, 1);
  } else if (slewing_) {
    slew_force(command);
    if (slewing_) command.reason(msg::FORCE_RESUMING);
  }
  rendered_n_ = common::to_eigen(command.force_n());
  command.header().sim_step(pose.servo_tick());
  command.header().sim_time_ns(pose.header().sim_time_ns());
  contacts.body_id(setup_.bodies.front().body->id);
  contacts.haptic_tick(tick_);
  contacts.fem_step(tissue.fem_step);
  contacts.layout_fingerprint(layout_fingerprint_);
  fill_tool_contacts({requests_.data(), request_count_}, tissue, contacts);
  // Where the FEM finds the tool: the proxy after this tick (the penalty
  // baseline's tool is the device).
  common::put(setup_.penalty ? device.position_m : response_.proxy().position_m,
              contacts.world_from_tool().position_m());
  common::put(device.orientation, contacts.world_from_tool().orientation());
  contacts.header().sim_step(pose.servo_tick());
  contacts.header().sim_time_ns(pose.header().sim_time_ns());
  ++tick_;

  relaxed_add<std::uint64_t>(metrics_.ticks, 1);
  relaxed_store(metrics_.tool_rows, static_cast<std::uint32_t>(tissue_rows));
  relaxed_store(metrics_.active_contacts, out.active_contacts);
  const auto without_w = static_cast<std::uint32_t>(
      rows_without_w_ +
      static_cast<std::size_t>(std::max(0, response_.report().load.missing_compliance)));
  relaxed_store(metrics_.missing_compliance, without_w);
  relaxed_add<std::uint64_t>(metrics_.tissue_rows_total, tissue_rows);
  relaxed_add<std::uint64_t>(metrics_.rows_without_compliance, without_w);
  relaxed_add<std::uint64_t>(metrics_.rows_without_compliance_touching, touching_without_w_);
  relaxed_store(metrics_.reaction_n, out.tissue_reaction_n);
  relaxed_store(metrics_.obstacle_reaction_n, response_.report().obstacle_reaction_n);
  const double force_n = out.force_n.norm();
  if (force_n > metrics_.peak_force_n.load(std::memory_order_relaxed))
    relaxed_store(metrics_.peak_force_n, force_n);
  const contact::TickReport& report = response_.report();
  if (report.load.diagonal_scale > 1.0 || report.load.indefinite) {
    relaxed_add<std::uint64_t>(metrics_.indefinite_w_ticks, 1);
    store_max(metrics_.w_diagonal_scale_max, report.load.diagonal_scale);
  }
  if (report.implausible_step) relaxed_add<std::uint64_t>(metrics_.refused_steps, 1);
  if (out.lost_track) {
    relaxed_add<std::uint64_t>(metrics_.lost_track_ticks, 1);
    if (!was_lost_) relaxed_add<std::uint64_t>(metrics_.lost_track_episodes, 1);
  }
  was_lost_ = out.lost_track;
  const double tick_us = elapsed_us(start);
  store_max(metrics_.tick_us_max, tick_us);
  store_max(metrics_.tick_us_peak, tick_us);
}

// No usable FEM state for kTissueLossTimeoutNs: the frozen tongue is not
// rendered. The force ramps from its value at the loss to zero over
// kLossRampTicks servo ticks, at most kResetSlewN a command, with no local
// stiffness; the proxy sits at the hand. The ContactSet repeats the last
// rendered tick's contacts and their forces (no requests): a FEM that is
// late rather than gone keeps the tongue under the blade where it was and
// its compliance block whole. An empty set released the tongue from the
// blade and emptied the block, so every late step of a FEM that missed its
// rate ended with a state that had W for none of the contacts, no rows and
// no force, and the force came back in steps (a 2-core station in real
// time); with the forces zero, the tongue held by the planes alone, it
// chattered again (1.7-2.0 N a tick in two of four cases of the fault
// test). A restarted FEM refuses these contacts: they answer a step it has
// not reached (fem_service ServiceStep::take); one reset since refuses them
// as stale.
void HapticLoop::lost_tick(const msg::DevicePose& pose, const contact::DeviceSample& device,
                           const TissueSnapshot& tissue, msg::ForceCommand& command,
                           msg::ContactSet& contacts) {
  if (!tissue_lost_) {
    tissue_lost_ = true;
    loss_from_n_ = rendered_n_;
    loss_servo_tick_ = pose.servo_tick();
    relaxed_add<std::uint64_t>(metrics_.tissue_losses, 1);
  }
  const double elapsed = pose.servo_tick() > loss_servo_tick_
                             ? static_cast<double>(pose.servo_tick() - loss_servo_tick_)
                             : 0.0;
  const Eigen::Vector3d target =
      loss_from_n_ * std::max(0.0, 1.0 - (elapsed + 1.0) / kLossRampTicks);
  Eigen::Vector3d change = target - rendered_n_;
  if (change.norm() > kResetSlewN) change *= kResetSlewN / change.norm();
  const Eigen::Vector3d force = device_idle_ ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                             : Eigen::Vector3d(rendered_n_ + change);
  command.device_id(pose.device_id());
  command.answered_pose_seq(device.pose_seq);
  common::put(device.position_m, command.answered_position_m());
  common::put(force, command.force_n());
  common::put(Eigen::Matrix3d(Eigen::Matrix3d::Zero()), command.stiffness_npm());
  common::put(Eigen::Vector3d(Eigen::Vector3d::Zero()), command.torque_nm());
  common::put(device.position_m, command.world_from_proxy().position_m());
  common::put(device.orientation, command.world_from_proxy().orientation());
  command.lost_track(false);
  common::put(Eigen::Vector3d(Eigen::Vector3d::Zero()), command.device_minus_proxy_m());
  command.tissue_reaction_n(0.0);
  command.active_contacts(0);
  command.fem_step(tissue.fem_step);
  command.reason(msg::FORCE_TISSUE_LOST);
  command.header().sim_step(pose.servo_tick());
  command.header().sim_time_ns(pose.header().sim_time_ns());
  rendered_n_ = force;
  slewing_ = false;

  contacts.body_id(setup_.bodies.front().body->id);
  contacts.haptic_tick(tick_);
  contacts.fem_step(tissue.fem_step);
  contacts.layout_fingerprint(layout_fingerprint_);
  fill_tool_contacts({}, tissue, contacts);
  // Where the contacts were found: the last tick's tool.
  common::put(tool_body_.world_from_body.translation(), contacts.world_from_tool().position_m());
  common::put(Eigen::Quaterniond(tool_body_.world_from_body.rotation()),
              contacts.world_from_tool().orientation());
  contacts.header().sim_step(pose.servo_tick());
  contacts.header().sim_time_ns(pose.header().sim_time_ns());
  ++tick_;
  relaxed_add<std::uint64_t>(metrics_.ticks, 1);
  relaxed_add<std::uint64_t>(metrics_.tissue_lost_ticks, 1);
  relaxed_store(metrics_.tool_rows, 0u);
  relaxed_store(metrics_.active_contacts, 0u);
  relaxed_store(metrics_.reaction_n, 0.0);
}

// The penalty baseline: each penetrating tissue row pushes its sphere with
// k_p d along n, as a force-only ContactSet entry (the FEM applies it and
// projects nothing); bone rows push the tool but not the tissue.
const contact::ForceOutput& HapticLoop::penalty_tick(const contact::DeviceSample& device,
                                                     const TissueSnapshot& tissue) {
  const contact::ForceOutput& out =
      penalty_.tick(device, {rows_.data(), row_count_}, tissue.fem_step);
  penalty_count_ = 0;
  for (const contact::SphereForce& f : penalty_.sphere_forces()) {
    const double magnitude = f.force_n.norm();
    if (!(magnitude > 0.0) || penalty_count_ == penalty_contacts_.size()) continue;
    fem::Contact& c = penalty_contacts_[penalty_count_++];
    c.sphere_id = f.sphere_id;
    c.kind = fem::ContactKind::kForceOnly;
    c.state = fem::ContactState::kActive;
    c.normal = f.force_n / magnitude;
    c.force_n = magnitude;
    c.hold_centre_m = tissue.spheres.centres_m()[f.sphere_id];
    c.plane_point_m = c.hold_centre_m;
    c.penetration_m = magnitude / setup_.penalty_settings.stiffness_npm;
  }
  for (const fem::Contact& c : tissue.tissue_obstacle_contacts()) {
    if (penalty_count_ == penalty_contacts_.size()) break;
    penalty_contacts_[penalty_count_++] = c;
  }
  return out;
}

// After a tissue reset the command's force moves at most kResetSlewN a
// tick toward the response's, with no local stiffness (the gateway would add
// K (x - x_k) on top), until it has caught up.
void HapticLoop::slew_force(msg::ForceCommand& command) {
  const Eigen::Vector3d wanted = common::to_eigen(command.force_n());
  const Eigen::Vector3d change = wanted - rendered_n_;
  if (slew_ticks_left_ > 0) --slew_ticks_left_;
  if (change.norm() <= kResetSlewN) {
    // Caught up; the slew ends once the window is over too (right after a
    // reset the response's force is small: the proxy settles, the contacts
    // come back, and then the force grows).
    if (slew_ticks_left_ == 0) slewing_ = false;
    return;
  }
  common::put(Eigen::Vector3d(rendered_n_ + change * (kResetSlewN / change.norm())),
              command.force_n());
  common::put(Eigen::Matrix3d(Eigen::Matrix3d::Zero()), command.stiffness_npm());
}

void HapticLoop::append_metrics(std::vector<std::pair<std::string, double>>& out) {
  const auto get = [](const auto& a) {
    return static_cast<double>(a.load(std::memory_order_relaxed));
  };
  out.emplace_back("fem_states_used", get(metrics_.snapshots));
  out.emplace_back("tool_rows", get(metrics_.tool_rows));
  out.emplace_back("anatomy_rows", get(metrics_.anatomy_rows));
  out.emplace_back("active_contacts", get(metrics_.active_contacts));
  out.emplace_back("rows_dropped", get(metrics_.rows_dropped));
  out.emplace_back("query_overflows", get(metrics_.query_overflows));
  out.emplace_back("missing_compliance", get(metrics_.missing_compliance));
  out.emplace_back("tissue_rows_total", get(metrics_.tissue_rows_total));
  out.emplace_back("rows_without_compliance", get(metrics_.rows_without_compliance));
  out.emplace_back("rows_without_compliance_touching",
                   get(metrics_.rows_without_compliance_touching));
  out.emplace_back("lost_track_ticks", get(metrics_.lost_track_ticks));
  out.emplace_back("indefinite_w_ticks", get(metrics_.indefinite_w_ticks));
  out.emplace_back("w_diagonal_scale_max", get(metrics_.w_diagonal_scale_max));
  out.emplace_back("refused_steps", get(metrics_.refused_steps));
  out.emplace_back("tissue_resets", get(metrics_.tissue_resets));
  out.emplace_back("tissue_losses", get(metrics_.tissue_losses));
  out.emplace_back("tissue_returns", get(metrics_.tissue_returns));
  out.emplace_back("fem_restarts_seen", get(metrics_.fem_writers));
  out.emplace_back("tissue_lost_ticks", get(metrics_.tissue_lost_ticks));
  out.emplace_back("device_idle_ticks", get(metrics_.device_idle_ticks));
  out.emplace_back("lost_track_episodes", get(metrics_.lost_track_episodes));
  out.emplace_back("tissue_reaction_n", get(metrics_.reaction_n));
  out.emplace_back("anatomy_reaction_n", get(metrics_.obstacle_reaction_n));
  out.emplace_back("peak_force_n", get(metrics_.peak_force_n));
  out.emplace_back("spheres", static_cast<double>(setup_.layout.size()));
  out.emplace_back("tick_us_max", metrics_.tick_us_max.exchange(0.0, std::memory_order_relaxed));
}

void HapticLoop::take_errors(std::vector<std::string>& errors) {
  const auto say = [&](const std::atomic<std::uint64_t>& count, std::uint64_t& said,
                       const char* what) {
    const std::uint64_t now = count.load(std::memory_order_relaxed);
    if (now == said) return;
    char text[200];
    std::snprintf(text, sizeof(text), "%s (%llu since start)", what,
                  static_cast<unsigned long long>(now));
    said = now;
    errors.emplace_back(text);
  };
  say(metrics_.tissue_losses, losses_said_,
      "FEM lost: no usable DeformationState for 50 ms; the tongue is not rendered, the force "
      "ramps to zero over 150 ms");
  say(metrics_.tissue_returns, returns_said_,
      "FEM back: DeformationStates again; the force resumes through the reset slew");
  say(metrics_.fem_writers, writers_said_,
      "a new FEM writer (the FEM service restarted, its tongue at rest): resumed through the "
      "reset slew");
  say(metrics_.device_silences, silences_said_,
      "DevicePose silent for 50 ms (the gateway lost or stalled): holding, no ForceCommand sent");
}

}  // namespace fahr::haptic_service
