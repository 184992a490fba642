// Digesting a DeformationState for the haptic tick (see tissue_snapshot.h).
#include "fahr/haptic_service/tissue_snapshot.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace fahr::haptic_service {
namespace {

// Tissue spheres in contact with (or within the margin of) the anatomy per
// state: the tongue resting on the floor of the mouth and pressed against
// the jaw reaches ~300 of them; a full buffer is flagged. With the tool's
// 64 rows and held spheres this stays within msg::MAX_CONTACTS (512).
constexpr std::size_t kObstacleContactCapacity = 384;
// Spheres this close to the anatomy are sent as constraints too (inactive
// while they keep clear): the FEM projects a state the haptic service saw
// one FEM step earlier, and with touching spheres alone the set flickers
// between none and hundreds as the tongue settles on the jaw, m.
constexpr double kObstacleMarginM = 0.5e-3;

}  // namespace

contact::TissueCompliance TissueSnapshot::compliance() const {
  contact::TissueCompliance c;
  c.fem_step = fem_step;
  if (compliance_count > 0) {
    c.sphere_ids = {compliance_ids.data(), compliance_count};
    const std::size_t k = compliance_count;
    if (have_compliance_normals) {
      c.w_mpn = {w_mpn.data(), 3 * k * k};
      c.normals = {compliance_normals.data(), 3 * k};
    } else {
      c.w_mpn = {w_mpn.data(), 9 * k * k};
    }
  }
  return c;
}

TissueDigest::TissueDigest(const HapticSetup& setup)
    : setup_(setup),
      positions_m_(3 * setup.mesh.node_count(), 0.0),
      obstacle_buffer_(kObstacleContactCapacity) {
  // Tissue against anatomy changes only with the FEM state, so the grid
  // distance is enough: off by a fraction of a cell at edges only.
  obstacle_query_.exact_narrow_phase = false;
  obstacle_query_.candidate_margin_m = kObstacleMarginM;
  // The anatomy is thick: the field's normal points the right way even with
  // the centre inside, so no approach memory (which visits every sphere
  // within the margin: most of the tongue's underside lies 0.37 mm off the jaw).
  obstacle_query_.approach_margin_m = 0.0;
  for (const std::size_t a : setup.tissue_obstacles) {
    const RigidField* field = setup.anatomy[a].get();
    collision::RigidBody body;
    body.id = field->scene_body->id;
    body.sdf = field->sdf.get();
    body.world_from_body = Eigen::Translation3d(field->scene_body->pose.position_m) *
                           field->scene_body->pose.orientation;
    obstacle_bodies_.push_back(body);
    obstacle_memory_.emplace_back(setup.layout.size());
  }
}

TissueSnapshot TissueDigest::make_snapshot() {
  TissueSnapshot s;
  s.spheres = collision::SphereState(setup_.layout);
  s.spheres.reset_to_rest(setup_.layout);
  s.tree = collision::SphereTree(setup_.layout);
  s.tree.refit(s.spheres);
  s.compliance_ids.assign(msg::MAX_COMPLIANCE_SPHERES, 0);
  s.w_mpn.assign(msg::MAX_COMPLIANCE_ENTRIES, 0.0f);
  s.free_centres_m.assign(msg::MAX_COMPLIANCE_COORDS, 0.0f);
  s.compliance_normals.assign(msg::MAX_COMPLIANCE_COORDS, 0.0f);
  s.free_shift_m.assign(msg::MAX_COMPLIANCE_SPHERES, 0.0f);
  s.compliance_index.assign(setup_.layout.size(), contact::kNoCompliance);
  s.obstacle_contacts.assign(kObstacleContactCapacity, fem::Contact{});
  s.obstacle_body_ids.assign(kObstacleContactCapacity, 0);
  if (setup_.collision == CollisionMethod::kTriangle) {
    s.triangles = std::make_unique<collision::TriangleBaseline>(
        setup_.triangles->boundary, setup_.triangles->surface_to_node, setup_.tool->surface);
  }
  // Until the FEM publishes, the tongue is at rest and may already lie on
  // the anatomy.
  query_obstacles(s);
  return s;
}

bool TissueDigest::plausible(const msg::DeformationState& state) const {
  // A non-finite compliance or free centre is never used: the whole state
  // is refused (counted as a bad state), as for a non-finite position.
  const auto finite = [](const auto& values) {
    return std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
  };
  return state.positions_m().size() == positions_m_.size() && finite(state.positions_m()) &&
         finite(state.compliance_mpn()) && finite(state.compliance_normals()) &&
         finite(state.compliance_free_centres_m());
}

bool TissueDigest::digest(const msg::DeformationState& state, TissueSnapshot& out) {
  const auto start = std::chrono::steady_clock::now();
  if (!plausible(state)) return false;
  const auto& x = state.positions_m();
  for (std::size_t i = 0; i < x.size(); ++i) positions_m_[i] = static_cast<double>(x[i]);
  if (!out.spheres.update(setup_.layout, positions_m_)) return false;  // a NaN from the FEM
  out.tree.refit(out.spheres);
  if (out.triangles) out.triangles->update(positions_m_);
  out.from_fem = true;
  out.fem_step = state.step();
  out.reset_epoch = state.reset_epoch();
  out.fem_writer = state.header().writer_id();
  query_obstacles(out);
  index_compliance(state, out);
  out.digest_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return true;
}

void TissueDigest::index_compliance(const msg::DeformationState& state, TissueSnapshot& out) {
  // The slot is reused: clear what its previous state indexed.
  for (std::size_t i = 0; i < out.compliance_count; ++i) {
    out.compliance_index[out.compliance_ids[i]] = contact::kNoCompliance;
  }
  out.compliance_count = 0;
  out.have_free_centres = false;
  const auto& ids = state.compliance_sphere_ids();
  const std::size_t k = std::min<std::size_t>(ids.size(), out.compliance_ids.size());
  out.have_compliance_normals = false;
  const bool along = !state.compliance_normals().empty();
  if (along && state.compliance_normals().size() < 3 * k) return;
  const std::size_t entries = along ? 3 * k * k : 9 * k * k;
  if (k == 0 || state.compliance_mpn().size() < entries)
    return;  // no usable W: rows use the fallback
  for (std::size_t i = 0; i < k; ++i) {
    // An id beyond the layout would index past the table: the whole W is
    // refused rather than solved with a row missing.
    if (ids[i] >= out.compliance_index.size()) return;
  }
  for (std::size_t i = 0; i < k; ++i) {
    out.compliance_ids[i] = ids[i];
    out.compliance_index[ids[i]] = static_cast<std::int32_t>(i);
  }
  std::copy_n(state.compliance_mpn().data(), entries, out.w_mpn.data());
  if (along) {
    std::copy_n(state.compliance_normals().data(), 3 * k, out.compliance_normals.data());
    out.have_compliance_normals = true;
  }
  out.compliance_count = k;
  // Without free centres no sphere has moved off its published centre.
  std::fill_n(out.free_shift_m.begin(), k, 0.0f);
  if (state.compliance_free_centres_m().size() >= 3 * k) {
    std::copy_n(state.compliance_free_centres_m().data(), 3 * k, out.free_centres_m.data());
    out.have_free_centres = true;
    const auto centres = out.spheres.centres_m();
    for (std::size_t i = 0; i < k; ++i) {
      const float* f = out.free_centres_m.data() + 3 * i;
      out.free_shift_m[i] =
          static_cast<float>((centres[ids[i]] - Eigen::Vector3d(f[0], f[1], f[2])).norm());
    }
  }
}

void TissueDigest::query_obstacles(TissueSnapshot& out) {
  obstacle_buffer_.clear();
  out.obstacle_overflow = false;
  for (std::size_t b = 0; b < obstacle_bodies_.size(); ++b) {
    const auto stats =
        collision::query_spheres(out.tree, out.spheres, obstacle_bodies_[b], obstacle_query_,
                                 obstacle_memory_[b], obstacle_buffer_);
    out.obstacle_overflow = out.obstacle_overflow || stats.overflowed;
  }
  out.obstacle_count = 0;
  for (const collision::SphereContact& s : obstacle_buffer_) {
    // Near ones too: the projection leaves a constraint that holds alone.
    fem::Contact& c = out.obstacle_contacts[out.obstacle_count];
    c.sphere_id = s.sphere_id;
    c.kind = fem::ContactKind::kObstacle;
    c.state = fem::ContactState::kActive;
    c.plane_point_m = s.point_m;
    c.normal = s.normal;
    c.hold_centre_m = out.spheres.centres_m()[s.sphere_id];
    c.penetration_m = s.depth_m;
    c.force_n = 0.0;  // a hard constraint: the FEM's projection alone resolves it
    out.obstacle_body_ids[out.obstacle_count] = s.body_id;
    ++out.obstacle_count;
  }
}

}  // namespace fahr::haptic_service
