// fill_spheres: grid, octree, hugging closure, then links (see fill_spheres.h).
#include "fahr/sphere_layout/fill_spheres.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "fahr/geometry/signed_distance_field.h"
#include "octree_fill.h"
#include "surface_anchor.h"
#include "surface_hugging.h"
#include "tet_links.h"

namespace fahr::sphere_layout {
namespace {

// The boundary field is queried exactly almost everywhere; its grid only
// speeds up the far field, so a coarse one (half a coarse radius) is enough.
constexpr double kSdfCellPerCoarseRadius = 0.5;

geometry::SurfaceMesh checked_boundary(const geometry::TetMesh& mesh,
                                       std::vector<geometry::Index>& surface_to_node) {
  if (mesh.tet_count() == 0 || mesh.node_count() == 0) {
    throw std::invalid_argument("sphere filling: the tet mesh is empty (0 tets); nothing to fill");
  }
  geometry::SurfaceMesh surface = mesh.boundary_surface(&surface_to_node);
  const auto& topo = surface.topology();
  if (!surface.is_closed() || !surface.is_manifold()) {
    std::ostringstream message;
    message << "sphere filling: the tet mesh's boundary is not a closed manifold surface ("
            << topo.boundary_edge_count << " open edges, " << topo.non_manifold_edge_count
            << " non-manifold edges, " << topo.non_manifold_vertex_count
            << " non-manifold vertices); inside and outside are undefined";
    throw std::invalid_argument(message.str());
  }
  return surface;
}

// The hugging sphere's tangent point (its nearest boundary point) and the
// face it lies on, for TetLinker::link_anchored.
detail::SphereLink anchored_link(detail::TetLinker& linker, const detail::CandidateSphere& c,
                                 const geometry::SurfaceMesh& boundary,
                                 const std::vector<geometry::Index>& surface_to_node,
                                 const geometry::SignedDistanceField& sdf, double depth_factor) {
  SurfaceAnchor tangent;
  if (!detail::nearest_face_point(boundary, surface_to_node, sdf, c.centre_m,
                                  std::numeric_limits<double>::infinity(), tangent)) {
    return linker.link(c.centre_m, c.radius_m, 0.0);
  }
  const Eigen::Vector3d weights(tangent.weights[0], tangent.weights[1], tangent.weights[2]);
  return linker.link_anchored(c.centre_m, c.radius_m, tangent.rest_point_m, tangent.nodes, weights,
                              depth_factor);
}

}  // namespace

SphereLayout fill_spheres(const geometry::TetMesh& mesh, const FillSettings& settings) {
  validate_fill_settings(settings);
  std::vector<geometry::Index> surface_to_node;
  const geometry::SurfaceMesh boundary = checked_boundary(mesh, surface_to_node);

  double mean_volume = 0.0;
  for (const auto& r : mesh.rest_data()) mean_volume += r.volume_m3;
  mean_volume /= static_cast<double>(mesh.tet_count());
  const double coarse_radius =
      std::cbrt(3.0 * settings.volume_ratio * mean_volume / (4.0 * std::numbers::pi));

  geometry::SdfOptions sdf_options;
  sdf_options.cell_size_m = kSdfCellPerCoarseRadius * coarse_radius;
  const geometry::SignedDistanceField sdf(boundary, sdf_options);

  std::vector<detail::CandidateSphere> candidates = detail::octree_fill(
      sdf, boundary.bounds_min(), boundary.bounds_max(), coarse_radius, settings);
  if (settings.surface_hugging) {
    const double finest = coarse_radius / std::ldexp(1.0, settings.refinement_levels);
    detail::add_surface_hugging_spheres(candidates, boundary, sdf,
                                        settings.hugging_radius_fraction * finest, settings);
  }
  if (candidates.empty()) {
    throw std::invalid_argument(
        "sphere filling: no sphere fits in the mesh; lower volume_ratio or raise "
        "refinement_levels");
  }

  detail::TetLinker linker(mesh, settings.max_linked_tets);
  std::vector<SphereRecord> records;
  std::vector<std::uint32_t> nodes, tets;
  std::vector<double> weights;
  std::vector<SurfaceAnchor> anchors(candidates.size());
  std::vector<std::uint8_t> has_anchor(candidates.size(), 0);
  records.reserve(candidates.size());
  for (const auto& c : candidates) {
    const double spread = c.origin == SphereOrigin::kHugging ? settings.hugging_weight_spread
                                                             : settings.weight_spread;
    const bool anchored =
        c.origin == SphereOrigin::kHugging && settings.hugging_anchor_depth_factor > 1.0;
    const detail::SphereLink link = anchored
                                        ? anchored_link(linker, c, boundary, surface_to_node, sdf,
                                                        settings.hugging_anchor_depth_factor)
                                        : linker.link(c.centre_m, c.radius_m, spread);
    SphereRecord r;
    r.rest_centre_m = link.centre_m;
    r.rest_radius_m = c.radius_m;
    r.level = c.level;
    r.origin = c.origin;
    r.first_link = static_cast<std::uint32_t>(nodes.size());
    r.link_count = static_cast<std::uint32_t>(link.nodes.size());
    r.first_tet = static_cast<std::uint32_t>(tets.size());
    r.tet_count = static_cast<std::uint32_t>(link.tets.size());
    for (const std::uint32_t t : link.tets)
      r.rest_linked_volume_m3 += mesh.rest_data()[t].volume_m3;
    nodes.insert(nodes.end(), link.nodes.begin(), link.nodes.end());
    weights.insert(weights.end(), link.weights.begin(), link.weights.end());
    tets.insert(tets.end(), link.tets.begin(), link.tets.end());
    // The anchor of the centre as linked (the point the FEM moves).
    const std::size_t i = records.size();
    has_anchor[i] = settings.surface_anchors && detail::nearest_face_point(
                                                    boundary, surface_to_node, sdf, link.centre_m,
                                                    c.radius_m + settings.anchor_gap_m, anchors[i])
                        ? 1
                        : 0;
    records.push_back(r);
  }
  SphereLayout layout(std::move(records), std::move(nodes), std::move(weights), std::move(tets),
                      mesh.tets(), mesh.node_count(), settings.refinement_levels, coarse_radius);
  layout.set_anchors(std::move(anchors), std::move(has_anchor));
  return layout;
}

}  // namespace fahr::sphere_layout
