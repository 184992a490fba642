// TetMesh: validation, rest data, boundary faces and statistics, once at load.
#include "fahr/geometry/tet_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

namespace fahr::geometry {
namespace {

// Outward faces of a positive tet (see tet_quality.cpp); face f is opposite node f.
constexpr int kTetFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using FaceKey = std::array<Index, 3>;

FaceKey sorted_key(Triangle t) {
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace

TetMesh::TetMesh(std::vector<Eigen::Vector3d> rest_positions_m, std::vector<Tet> tets)
    : rest_positions_(std::move(rest_positions_m)), tets_(std::move(tets)) {
  for (std::size_t n = 0; n < rest_positions_.size(); ++n) {
    if (!rest_positions_[n].allFinite()) {
      throw std::invalid_argument("node " + std::to_string(n) + ": non-finite position");
    }
  }
  const auto node_count = static_cast<std::int64_t>(rest_positions_.size());
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    for (Index n : tets_[t]) {
      if (n < 0 || n >= node_count) {
        throw std::invalid_argument("tet " + std::to_string(t) + ": node index " +
                                    std::to_string(n) + " out of range [0, " +
                                    std::to_string(node_count) + ")");
      }
    }
  }
  compute_rest_data();
  compute_boundary();
}

void TetMesh::compute_rest_data() {
  rest_data_.resize(tets_.size());
  quality_ = TetQualityStats{};
  quality_.tet_count = tets_.size();
  quality_.min_volume_m3 = std::numeric_limits<double>::infinity();
  quality_.max_volume_m3 = -std::numeric_limits<double>::infinity();
  quality_.min_dihedral_rad = std::numeric_limits<double>::infinity();
  quality_.max_dihedral_rad = 0.0;
  quality_.min_radius_ratio = std::numeric_limits<double>::infinity();
  double ratio_sum = 0.0;
  std::vector<bool> used(rest_positions_.size(), false);
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    const Tet& tet = tets_[t];
    const Eigen::Vector3d& x0 = rest_positions_[tet[0]];
    const Eigen::Vector3d& x1 = rest_positions_[tet[1]];
    const Eigen::Vector3d& x2 = rest_positions_[tet[2]];
    const Eigen::Vector3d& x3 = rest_positions_[tet[3]];
    const TetShape shape = tet_shape(x0, x1, x2, x3);
    if (shape.volume_m3 <= 0.0 || is_flat_volume(shape.volume_m3, x0, x1, x2, x3)) {
      throw std::invalid_argument("tet " + std::to_string(t) + ": non-positive volume " +
                                  std::to_string(shape.volume_m3) + " m^3 (inverted or flat)");
    }
    rest_data_[t].volume_m3 = shape.volume_m3;
    for (Index n : tet) {
      used[n] = true;
    }
    quality_.min_volume_m3 = std::min(quality_.min_volume_m3, shape.volume_m3);
    quality_.max_volume_m3 = std::max(quality_.max_volume_m3, shape.volume_m3);
    quality_.total_volume_m3 += shape.volume_m3;
    quality_.min_dihedral_rad = std::min(quality_.min_dihedral_rad, shape.min_dihedral_rad);
    quality_.max_dihedral_rad = std::max(quality_.max_dihedral_rad, shape.max_dihedral_rad);
    quality_.min_radius_ratio = std::min(quality_.min_radius_ratio, shape.radius_ratio);
    ratio_sum += shape.radius_ratio;
    quality_.sliver_count += is_sliver(shape) ? 1u : 0u;
    quality_.poor_radius_ratio_count += shape.radius_ratio < kPoorRadiusRatio ? 1u : 0u;
  }
  if (tets_.empty()) {
    quality_.min_volume_m3 = quality_.max_volume_m3 = 0.0;
    quality_.min_dihedral_rad = 0.0;
    quality_.min_radius_ratio = 0.0;
  } else {
    const auto count = static_cast<double>(tets_.size());
    quality_.mean_volume_m3 = quality_.total_volume_m3 / count;
    quality_.mean_radius_ratio = ratio_sum / count;
  }
  quality_.unreferenced_node_count =
      static_cast<std::size_t>(std::count(used.begin(), used.end(), false));
}

void TetMesh::compute_boundary() {
  // Sort all tet faces by their node set: a face seen once is on the boundary,
  // twice is interior, more is a broken mesh.
  struct FaceRecord {
    FaceKey key;
    Index tet;
    int local;
  };
  std::vector<FaceRecord> faces;
  faces.reserve(tets_.size() * 4);
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    for (int f = 0; f < 4; ++f) {
      const Triangle tri = {tets_[t][kTetFaces[f][0]], tets_[t][kTetFaces[f][1]],
                            tets_[t][kTetFaces[f][2]]};
      faces.push_back({sorted_key(tri), static_cast<Index>(t), f});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const FaceRecord& l, const FaceRecord& r) {
    return std::tie(l.key, l.tet, l.local) < std::tie(r.key, r.tet, r.local);
  });
  boundary_faces_.clear();
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) {
      ++j;
    }
    if (j - i > 2) {
      throw std::invalid_argument(
          "face (" + std::to_string(faces[i].key[0]) + ", " + std::to_string(faces[i].key[1]) +
          ", " + std::to_string(faces[i].key[2]) + ") is shared by " + std::to_string(j - i) +
          " tets (at most 2 allowed); first tet " + std::to_string(faces[i].tet));
    }
    if (j - i == 1) {
      const Tet& tet = tets_[faces[i].tet];
      const int f = faces[i].local;
      boundary_faces_.push_back(
          {{tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]}, faces[i].tet, 0});
    }
    i = j;
  }
}

std::size_t TetMesh::assign_boundary_markers(const std::vector<Triangle>& faces,
                                             const std::vector<int>& markers) {
  std::vector<std::pair<FaceKey, std::size_t>> lookup;
  lookup.reserve(boundary_faces_.size());
  for (std::size_t b = 0; b < boundary_faces_.size(); ++b) {
    lookup.emplace_back(sorted_key(boundary_faces_[b].nodes), b);
  }
  std::sort(lookup.begin(), lookup.end());
  std::size_t not_found = 0;
  for (std::size_t i = 0; i < faces.size() && i < markers.size(); ++i) {
    const FaceKey key = sorted_key(faces[i]);
    const auto it =
        std::lower_bound(lookup.begin(), lookup.end(), std::make_pair(key, std::size_t{0}));
    if (it == lookup.end() || it->first != key) {
      ++not_found;
      continue;
    }
    boundary_faces_[it->second].marker = markers[i];
  }
  return not_found;
}

SurfaceMesh TetMesh::boundary_surface(std::vector<Index>* surface_to_node) const {
  std::vector<Index> node_to_surface(rest_positions_.size(), -1);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Index> to_node;
  std::vector<Triangle> triangles;
  triangles.reserve(boundary_faces_.size());
  for (const BoundaryFace& face : boundary_faces_) {
    Triangle tri{};
    for (std::size_t k = 0; k < 3; ++k) {
      const Index n = face.nodes[k];
      if (node_to_surface[n] < 0) {
        node_to_surface[n] = static_cast<Index>(vertices.size());
        vertices.push_back(rest_positions_[n]);
        to_node.push_back(n);
      }
      tri[k] = node_to_surface[n];
    }
    triangles.push_back(tri);
  }
  if (surface_to_node != nullptr) {
    *surface_to_node = std::move(to_node);
  }
  return SurfaceMesh(std::move(vertices), std::move(triangles));
}

}  // namespace fahr::geometry
