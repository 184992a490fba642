// Triangle-level baseline on Bullet's GImpact box trees (see triangle_baseline.h).
// Bullet is built here in double precision (bullet-float64), so the header
// flag BT_USE_DOUBLE_PRECISION is set for this file only (CMakeLists).
#include "fahr/collision/triangle_baseline.h"

#include <BulletCollision/Gimpact/btGImpactBvh.h>
#include <BulletCollision/Gimpact/btTriangleShapeEx.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fahr::collision {
namespace {

btVector3 to_bt(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

// Bullet reads triangles through this interface; the vertices are ours, so
// moving them and calling the tree's update() refits without a rebuild.
class MeshPrimitives final : public btPrimitiveManagerBase {
 public:
  // Boxes grow by this, m: a flat triangle's box is flat, so without it a
  // tissue triangle pushed wholly behind a tool face would pair with nothing.
  double box_margin_m = 0.0;
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<geometry::Triangle> triangles;

  bool is_trimesh() const override { return true; }
  int get_primitive_count() const override { return static_cast<int>(triangles.size()); }
  void get_primitive_box(int index, btAABB& box) const override {
    const auto& t = triangles[static_cast<std::size_t>(index)];
    const Eigen::Vector3d lo =
        vertices_m[t[0]].cwiseMin(vertices_m[t[1]]).cwiseMin(vertices_m[t[2]]);
    const Eigen::Vector3d hi =
        vertices_m[t[0]].cwiseMax(vertices_m[t[1]]).cwiseMax(vertices_m[t[2]]);
    box.m_min = to_bt(lo - Eigen::Vector3d::Constant(box_margin_m));
    box.m_max = to_bt(hi + Eigen::Vector3d::Constant(box_margin_m));
  }
  void get_primitive_triangle(int index, btPrimitiveTriangle& triangle) const override {
    const auto& t = triangles[static_cast<std::size_t>(index)];
    for (int k = 0; k < 3; ++k) triangle.m_vertices[k] = to_bt(vertices_m[t[k]]);
    triangle.m_margin = 0.0;  // Bullet's default margin is 1 cm: far beyond a tongue's contacts
  }
};

// Inside the triangle's prism: the projection of p lies in the triangle.
bool in_prism(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
  return n.dot((b - a).cross(p - a)) >= 0.0 && n.dot((c - b).cross(p - b)) >= 0.0 &&
         n.dot((a - c).cross(p - c)) >= 0.0;
}

// The face nearest a vertex among those whose prism holds it: its signed
// distance d (< 0 behind the face), the point on the tool surface, the normal
// from the tool toward the tissue and the tissue vertex acted on.
struct Best {
  double distance = std::numeric_limits<double>::infinity();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  std::int32_t acting_tissue_vertex = -1;
};

}  // namespace

struct TriangleBaseline::Impl {
  MeshPrimitives tissue, tool;
  std::vector<geometry::Index> surface_to_node;
  std::vector<Eigen::Vector3d> tool_normals;  // tool frame
  btGImpactBvh tissue_tree, tool_tree;
  btPairSet pairs;
  std::vector<Best> tissue_best, tool_best;
  std::vector<std::uint32_t> tissue_stamp, tool_stamp, touched_tissue, touched_tool;
  std::uint32_t stamp = 0;
  std::uint64_t refits = 0;
  std::uint64_t builds = 0;
};

TriangleBaseline::TriangleBaseline(const geometry::SurfaceMesh& tissue,
                                   std::vector<geometry::Index> surface_to_node,
                                   const geometry::SurfaceMesh& tool)
    : impl_(std::make_unique<Impl>()) {
  if (tissue.triangle_count() == 0 || tool.triangle_count() == 0) {
    throw std::invalid_argument(
        "triangle baseline: the tissue or the tool surface has no triangles");
  }
  if (surface_to_node.size() != tissue.vertex_count()) {
    throw std::invalid_argument("triangle baseline: surface_to_node has " +
                                std::to_string(surface_to_node.size()) + " entries for " +
                                std::to_string(tissue.vertex_count()) + " tissue vertices");
  }
  Impl& m = *impl_;
  m.tissue.vertices_m = tissue.vertices();
  m.tissue.triangles = tissue.triangles();
  m.tool.vertices_m = tool.vertices();
  m.tool.triangles = tool.triangles();
  m.tool_normals = tool.face_normals();
  m.tool.box_margin_m = kMaxFaceDepthM;  // the depth range the narrow phase looks in
  m.surface_to_node = std::move(surface_to_node);
  m.tissue_tree.setPrimitiveManager(&m.tissue);
  m.tool_tree.setPrimitiveManager(&m.tool);
  m.tissue_tree.buildSet();
  m.tool_tree.buildSet();
  m.builds = 1;
  m.pairs.reserve(1 << 16);
  m.tissue_best.resize(tissue.vertex_count());
  m.tool_best.resize(tool.vertex_count());
  m.tissue_stamp.assign(tissue.vertex_count(), 0);
  m.tool_stamp.assign(tool.vertex_count(), 0);
}

TriangleBaseline::~TriangleBaseline() = default;

void TriangleBaseline::update(std::span<const double> positions_m) {
  Impl& m = *impl_;
  for (std::size_t i = 0; i < m.tissue.vertices_m.size(); ++i) {
    const auto node = static_cast<std::size_t>(m.surface_to_node[i]);
    m.tissue.vertices_m[i] = Eigen::Vector3d(positions_m[3 * node], positions_m[3 * node + 1],
                                             positions_m[3 * node + 2]);
  }
  m.tissue_tree.update();  // refit: same topology, new boxes
  ++m.refits;
}

void TriangleBaseline::collide(const Eigen::Isometry3d& world_from_tool,
                               std::vector<TriangleContact>& out, double candidate_margin_m) {
  Impl& m = *impl_;
  // Beyond the tool boxes' growth a candidate's pair would not be found.
  // (A NaN margin is none.)
  const double margin = std::isfinite(candidate_margin_m)
                            ? std::clamp(candidate_margin_m, 0.0, 0.99 * kMaxFaceDepthM)
                            : 0.0;
  out.clear();
  m.pairs.resizeNoInitialize(0);  // keeps the capacity; resize() would copy an uninitialised pair
  btTransform tool_pose;
  const Eigen::Matrix3d r = world_from_tool.linear();
  tool_pose.setBasis(
      btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)));
  tool_pose.setOrigin(to_bt(world_from_tool.translation()));
  btTransform identity;
  identity.setIdentity();
  btGImpactBvh::find_collision(&m.tissue_tree, identity, &m.tool_tree, tool_pose, m.pairs);

  ++m.stamp;
  m.touched_tissue.clear();
  m.touched_tool.clear();
  // Which side a vertex is on is decided by the nearest face whose prism
  // holds it: behind it, inside the other body. Behind a farther face is not
  // enough: 0.5 mm above a 1.2 mm blade, a tongue vertex is 1.7 mm behind the
  // blade's underside but in front of its top face.
  auto offer = [&](std::vector<Best>& best, std::vector<std::uint32_t>& stamp,
                   std::vector<std::uint32_t>& touched, std::uint32_t vertex, double distance,
                   const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                   std::int32_t acting_tissue_vertex) {
    if (stamp[vertex] != m.stamp) {
      stamp[vertex] = m.stamp;
      best[vertex] = Best{};
      touched.push_back(vertex);
    }
    if (std::abs(distance) < std::abs(best[vertex].distance)) {
      best[vertex] = Best{distance, point, normal, acting_tissue_vertex};
    }
  };
  for (int k = 0; k < m.pairs.size(); ++k) {
    const auto& tt = m.tissue.triangles[static_cast<std::size_t>(m.pairs[k].m_index1)];
    const auto& st = m.tool.triangles[static_cast<std::size_t>(m.pairs[k].m_index2)];
    const Eigen::Vector3d s[3] = {world_from_tool * m.tool.vertices_m[st[0]],
                                  world_from_tool * m.tool.vertices_m[st[1]],
                                  world_from_tool * m.tool.vertices_m[st[2]]};
    const Eigen::Vector3d sn = r * m.tool_normals[static_cast<std::size_t>(m.pairs[k].m_index2)];
    const Eigen::Vector3d t[3] = {m.tissue.vertices_m[tt[0]], m.tissue.vertices_m[tt[1]],
                                  m.tissue.vertices_m[tt[2]]};
    const Eigen::Vector3d tn_raw = (t[1] - t[0]).cross(t[2] - t[0]);
    const double tn_len = tn_raw.norm();
    for (int v = 0; v < 3; ++v) {  // tissue vertices behind the tool face
      const double d = sn.dot(t[v] - s[0]);
      if (std::abs(d) < kMaxFaceDepthM && in_prism(t[v], s[0], s[1], s[2], sn)) {
        offer(m.tissue_best, m.tissue_stamp, m.touched_tissue, static_cast<std::uint32_t>(tt[v]), d,
              t[v] - d * sn, sn, static_cast<std::int32_t>(tt[v]));
      }
    }
    if (tn_len <= 0.0) continue;  // a collapsed tissue triangle has no side
    const Eigen::Vector3d tn = tn_raw / tn_len;
    for (int v = 0; v < 3; ++v) {  // tool vertices behind the tissue face
      const double d = tn.dot(s[v] - t[0]);
      if (std::abs(d) < kMaxFaceDepthM && in_prism(s[v], t[0], t[1], t[2], tn)) {
        int nearest = 0;
        for (int c = 1; c < 3; ++c) {
          if ((t[c] - s[v]).squaredNorm() < (t[nearest] - s[v]).squaredNorm()) nearest = c;
        }
        offer(m.tool_best, m.tool_stamp, m.touched_tool, static_cast<std::uint32_t>(st[v]), d, s[v],
              -tn, static_cast<std::int32_t>(tt[nearest]));
      }
    }
  }
  // Behind the nearest face: a contact; in front of it within the margin: a
  // candidate (depth <= 0).
  for (const std::uint32_t v : m.touched_tissue) {
    const Best& b = m.tissue_best[v];
    if (b.distance < margin) {
      out.push_back({b.point, b.normal, -b.distance, static_cast<std::int32_t>(v), -1,
                     b.acting_tissue_vertex});
    }
  }
  for (const std::uint32_t v : m.touched_tool) {
    const Best& b = m.tool_best[v];
    if (b.distance < margin) {
      out.push_back({b.point, b.normal, -b.distance, -1, static_cast<std::int32_t>(v),
                     b.acting_tissue_vertex});
    }
  }
}

std::uint64_t TriangleBaseline::refit_count() const {
  return impl_->refits;
}
std::uint64_t TriangleBaseline::rebuild_count() const {
  return impl_->builds - 1;
}

}  // namespace fahr::collision
