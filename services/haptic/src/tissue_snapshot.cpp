// Digesting a DeformationState for the haptic tick (see tissue_snapshot.h).
#include "fahr/haptic_service/tissue_snapshot.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "fahr/common/packed_symmetric.h"

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
  // Every body's block at its largest.
  const std::size_t n = setup_.bodies.size();
  s.body_fem_steps.assign(n, 0);
  s.compliance_ids.assign(n * msg::MAX_COMPLIANCE_SPHERES, 0);
  s.w_mpn.assign(n * n * msg::MAX_COMPLIANCE_ENTRIES, 0.0f);
  s.free_centres_m.assign(n * msg::MAX_COMPLIANCE_COORDS, 0.0f);
  s.compliance_normals.assign(n * msg::MAX_COMPLIANCE_COORDS, 0.0f);
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

std::size_t TissueDigest::body_index(std::uint32_t body_id) const {
  std::size_t b = 0;
  while (b < setup_.bodies.size() && setup_.bodies[b].body->id != body_id) ++b;
  return b;
}

bool TissueDigest::plausible(const msg::DeformationState& state) const {
  // A non-finite compliance or free centre is never used: the whole state
  // is refused (counted as a bad state), as for a non-finite position.
  const auto finite = [](const auto& values) {
    return std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
  };
  const std::size_t b = body_index(state.body_id());
  return b < setup_.bodies.size() &&
         state.positions_m().size() == 3 * setup_.bodies[b].mesh.node_count() &&
         finite(state.positions_m()) && finite(state.compliance_mpn()) &&
         finite(state.compliance_normals()) && finite(state.compliance_free_centres_m());
}

bool TissueDigest::digest(std::span<const msg::DeformationState* const> states,
                          TissueSnapshot& out) {
  const auto start = std::chrono::steady_clock::now();
  if (states.size() != setup_.bodies.size()) return false;
  for (std::size_t b = 0; b < states.size(); ++b) {
    const TissueBody& body = setup_.bodies[b];
    if (states[b] == nullptr || states[b]->body_id() != body.body->id || !plausible(*states[b]))
      return false;
    const auto& x = states[b]->positions_m();
    double* to = positions_m_.data() + 3 * body.first_node;
    for (std::size_t i = 0; i < x.size(); ++i) to[i] = static_cast<double>(x[i]);
  }
  if (!out.spheres.update(setup_.layout, positions_m_)) return false;  // a NaN from the FEM
  out.tree.refit(out.spheres);
  if (out.triangles) out.triangles->update(positions_m_);
  out.from_fem = true;
  out.fem_step = states.front()->step();
  out.reset_epoch = 0;
  for (std::size_t b = 0; b < states.size(); ++b) {
    out.body_fem_steps[b] = states[b]->step();
    out.reset_epoch += states[b]->reset_epoch();
  }
  out.fem_writer = states.front()->header().writer_id();
  query_obstacles(out);
  index_compliance(states, out);
  out.digest_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return true;
}

namespace {

// A body's usable W block: its sphere count k (0: none usable) and whether
// it is along normals.
struct Block {
  std::size_t k = 0;
  bool along = false;
};

Block usable_block(const msg::DeformationState& state, std::size_t capacity,
                   std::size_t layout_size) {
  const auto& ids = state.compliance_sphere_ids();
  Block block;
  block.k = std::min<std::size_t>(ids.size(), capacity);
  block.along = !state.compliance_normals().empty();
  if (block.along && state.compliance_normals().size() < 3 * block.k) return {};
  const std::size_t entries =
      block.along ? 3 * block.k * block.k : common::packed_upper_size(3 * block.k);
  if (block.k == 0 || state.compliance_mpn().size() < entries) return {};
  // An id beyond the layout would index past the table: the whole block is
  // refused rather than solved with a row missing.
  for (std::size_t i = 0; i < block.k; ++i) {
    if (ids[i] >= layout_size) return {};
  }
  return block;
}

}  // namespace

void TissueDigest::index_compliance(std::span<const msg::DeformationState* const> states,
                                    TissueSnapshot& out) {
  // The slot is reused: clear what its previous state indexed.
  for (std::size_t i = 0; i < out.compliance_count; ++i) {
    out.compliance_index[out.compliance_ids[i]] = contact::kNoCompliance;
  }
  out.compliance_count = 0;
  out.have_free_centres = false;
  out.have_compliance_normals = false;
  // Each body's block (no usable W: its rows use the fallback), all along
  // normals or none: the scene decides for every body.
  std::array<Block, kMaxTissueBodies> blocks{};
  std::size_t total = 0;
  bool along = false;
  bool free_centres = true;
  for (std::size_t b = 0; b < states.size(); ++b) {
    blocks[b] =
        usable_block(*states[b], msg::MAX_COMPLIANCE_SPHERES, setup_.bodies[b].layout.size());
    if (blocks[b].k == 0) continue;
    if (total > 0 && blocks[b].along != along) return;  // mixed kinds: no W at all
    along = blocks[b].along;
    total += blocks[b].k;
    free_centres = free_centres && states[b]->compliance_free_centres_m().size() >= 3 * blocks[b].k;
  }
  if (total == 0) return;
  const std::size_t columns = along ? total : 3 * total;  // W's row length
  if (states.size() > 1) std::fill_n(out.w_mpn.begin(), 3 * total * columns, 0.0f);
  std::size_t first = 0;  // the block's first sphere in the joined W
  for (std::size_t b = 0; b < states.size(); ++b) {
    const std::size_t k = blocks[b].k;
    if (k == 0) continue;
    const msg::DeformationState& state = *states[b];
    const std::uint32_t offset = setup_.bodies[b].first_sphere;
    const auto& ids = state.compliance_sphere_ids();
    for (std::size_t i = 0; i < k; ++i) {
      out.compliance_ids[first + i] = ids[i] + offset;
      out.compliance_index[ids[i] + offset] = static_cast<std::int32_t>(first + i);
    }
    // The block's rows, each into its place in the joined rows (3x3 blocks
    // arrive as their upper triangle).
    if (along) {
      for (std::size_t r = 0; r < 3 * k; ++r) {
        std::copy_n(state.compliance_mpn().data() + r * k, k,
                    out.w_mpn.data() + (3 * first + r) * columns + first);
      }
    } else {
      common::unpack_upper(state.compliance_mpn().data(), 3 * k,
                           out.w_mpn.data() + 3 * first * columns + 3 * first, columns);
    }
    if (along) {
      std::copy_n(state.compliance_normals().data(), 3 * k,
                  out.compliance_normals.data() + 3 * first);
    }
    if (free_centres) {
      std::copy_n(state.compliance_free_centres_m().data(), 3 * k,
                  out.free_centres_m.data() + 3 * first);
    }
    first += k;
  }
  out.have_compliance_normals = along;
  out.compliance_count = total;
  out.have_free_centres = free_centres;
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
