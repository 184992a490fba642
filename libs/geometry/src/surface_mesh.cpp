// SurfaceMesh: normals, pseudo-normals and topology checks, once at construction.
#include "fahr/geometry/surface_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace fahr::geometry {
namespace {

bool has_repeated_index(const Triangle& t) {
  return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

// Angle (rad) between two edge vectors; 0 when one has zero length, so
// degenerate corners add nothing to a pseudo-normal.
double corner_angle(const Eigen::Vector3d& e1, const Eigen::Vector3d& e2) {
  const double cross = e1.cross(e2).norm();
  const double dot = e1.dot(e2);
  if (cross == 0.0 && dot == 0.0) {
    return 0.0;
  }
  return std::atan2(cross, dot);
}

Eigen::Vector3d normalized_or(const Eigen::Vector3d& v, const Eigen::Vector3d& fallback) {
  const double n = v.norm();
  return n > 0.0 ? Eigen::Vector3d(v / n) : fallback;
}

// Union-find over triangle corners, to count the fans around each vertex.
class CornerSets {
 public:
  explicit CornerSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void join(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<std::size_t> parent_;
};

std::size_t corner_of(const Triangle& t, std::size_t tri, Index vertex) {
  for (std::size_t k = 0; k < 3; ++k) {
    if (t[k] == vertex) {
      return 3 * tri + k;
    }
  }
  return 3 * tri;  // unreachable for a triangle that holds the vertex
}

}  // namespace

SurfaceMesh::SurfaceMesh(std::vector<Eigen::Vector3d> vertices_m, std::vector<Triangle> triangles)
    : vertices_(std::move(vertices_m)), triangles_(std::move(triangles)) {
  const auto count = static_cast<std::int64_t>(vertices_.size());
  for (std::size_t v = 0; v < vertices_.size(); ++v) {
    if (!vertices_[v].allFinite()) {
      throw std::invalid_argument("vertex " + std::to_string(v) + ": non-finite position");
    }
  }
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    for (Index v : triangles_[t]) {
      if (v < 0 || v >= count) {
        throw std::invalid_argument("triangle " + std::to_string(t) + ": vertex index " +
                                    std::to_string(v) + " out of range [0, " +
                                    std::to_string(count) + ")");
      }
    }
  }
  if (!vertices_.empty()) {
    bounds_min_ = bounds_max_ = vertices_[0];
    for (const Eigen::Vector3d& v : vertices_) {
      bounds_min_ = bounds_min_.cwiseMin(v);
      bounds_max_ = bounds_max_.cwiseMax(v);
    }
  }
  compute_normals_and_topology();
}

void SurfaceMesh::compute_normals_and_topology() {
  const std::size_t tri_count = triangles_.size();
  face_normals_.assign(tri_count, Eigen::Vector3d::Zero());
  vertex_normals_.assign(vertices_.size(), Eigen::Vector3d::Zero());
  edge_normals_.assign(tri_count,
                       {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  topology_ = SurfaceTopology{};

  for (std::size_t t = 0; t < tri_count; ++t) {
    const Triangle& tri = triangles_[t];
    const Eigen::Vector3d cross =
        (vertices_[tri[1]] - vertices_[tri[0]]).cross(vertices_[tri[2]] - vertices_[tri[0]]);
    const double norm = cross.norm();
    if (norm == 0.0 || has_repeated_index(tri)) {
      ++topology_.degenerate_triangle_count;
      continue;
    }
    face_normals_[t] = cross / norm;
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& here = vertices_[tri[k]];
      const double angle =
          corner_angle(vertices_[tri[(k + 1) % 3]] - here, vertices_[tri[(k + 2) % 3]] - here);
      vertex_normals_[tri[k]] += angle * face_normals_[t];
    }
  }
  for (Eigen::Vector3d& n : vertex_normals_) {
    n = normalized_or(n, Eigen::Vector3d::Zero());
  }

  // Half-edges grouped by their undirected edge.
  struct HalfEdge {
    Index low, high;
    Index tri;
    int local;     // edge k = (v_k, v_{k+1})
    bool forward;  // v_k < v_{k+1}
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * tri_count);
  for (std::size_t t = 0; t < tri_count; ++t) {
    const Triangle& tri = triangles_[t];
    if (has_repeated_index(tri)) {
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const Index a = tri[static_cast<std::size_t>(k)];
      const Index b = tri[static_cast<std::size_t>((k + 1) % 3)];
      half_edges.push_back({std::min(a, b), std::max(a, b), static_cast<Index>(t), k, a < b});
    }
  }
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& l, const HalfEdge& r) {
    return std::tie(l.low, l.high, l.tri, l.local) < std::tie(r.low, r.high, r.tri, r.local);
  });
  CornerSets corners(3 * tri_count);
  for (std::size_t i = 0; i < half_edges.size();) {
    std::size_t j = i + 1;
    while (j < half_edges.size() && half_edges[j].low == half_edges[i].low &&
           half_edges[j].high == half_edges[i].high) {
      ++j;
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t h = i; h < j; ++h) {
      sum += face_normals_[half_edges[h].tri];
    }
    const Eigen::Vector3d normal = normalized_or(sum, face_normals_[half_edges[i].tri]);
    for (std::size_t h = i; h < j; ++h) {
      edge_normals_[half_edges[h].tri][static_cast<std::size_t>(half_edges[h].local)] = normal;
    }
    if (j - i == 1) {
      ++topology_.boundary_edge_count;
    } else if (j - i > 2) {
      ++topology_.non_manifold_edge_count;
    } else {
      const HalfEdge& e1 = half_edges[i];
      const HalfEdge& e2 = half_edges[i + 1];
      if (e1.forward == e2.forward) {
        ++topology_.inconsistent_edge_count;
      }
      const Eigen::Vector3d& n1 = face_normals_[e1.tri];
      const Eigen::Vector3d& n2 = face_normals_[e2.tri];
      if (n1.squaredNorm() > 0.0 && n2.squaredNorm() > 0.0 && (n1 + n2).norm() < kFoldedNormalSum) {
        ++topology_.folded_edge_count;
      }
      for (Index v : {e1.low, e1.high}) {
        corners.join(corner_of(triangles_[e1.tri], static_cast<std::size_t>(e1.tri), v),
                     corner_of(triangles_[e2.tri], static_cast<std::size_t>(e2.tri), v));
      }
    }
    i = j;
  }

  // A vertex whose corners fall into more than one set has several fans (two cones touching at a
  // tip).
  std::vector<std::size_t> first_root(vertices_.size(), SIZE_MAX);
  std::vector<bool> flagged(vertices_.size(), false);
  for (std::size_t t = 0; t < tri_count; ++t) {
    if (has_repeated_index(triangles_[t])) {
      continue;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const Index v = triangles_[t][k];
      const std::size_t root = corners.find(3 * t + k);
      if (first_root[v] == SIZE_MAX) {
        first_root[v] = root;
      } else if (first_root[v] != root && !flagged[v]) {
        flagged[v] = true;
        ++topology_.non_manifold_vertex_count;
      }
    }
  }
}

double SurfaceMesh::enclosed_volume_m3() const {
  double six_volume = 0.0;
  for (const Triangle& t : triangles_) {
    six_volume += vertices_[t[0]].dot(vertices_[t[1]].cross(vertices_[t[2]]));
  }
  return six_volume / 6.0;
}

}  // namespace fahr::geometry
