// The detectors' common, independent reference: the FEM tongue driven by
// contacts of points of its own boundary. Each point is a contact of radius
// 0 projected out of the blade's field, with the normal from the point's
// last position outside (the spheres' pre-penetration rule). Neither the
// AIST nor the triangle baseline takes part, so states driven this way can
// be shown to both and judged the same.
//
// Which points: with subdivision 1 the boundary nodes only (one node,
// weight 1). The blade's 1.2 mm plate then pokes its rounded rim through the
// middle of the tongue's 2.6 mm faces, up to 2 mm deep, while every node
// lies on the blade: a state no resolved contact would leave. With
// subdivision N every boundary face is also sampled at the barycentric
// points (i, j, k) / N (each edge point once), carried by the face's three
// nodes with those weights: the rim then meets a point about edge / N away
// and the face is pushed out as a whole. With N > 1 this is the
// triangle-resolved reference the AIST's depth is judged against.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/contact_set.h"
#include "fahr/fem/sphere_links.h"
#include "scene.h"

namespace fahr::aist_bench {

class SurfaceContacts {
 public:
  // subdivision >= 1: segments per face edge (1: the nodes only).
  SurfaceContacts(const Scene& scene, int subdivision);

  // The contacts of the boundary points of `body` with the blade at
  // world_from_blade into `set` (cleared; stamped with the body's step).
  void fill(const fem::Body& body, const Eigen::Isometry3d& world_from_blade, fem::ContactSet& set);
  const fem::SphereLinks& links() const { return links_; }
  std::size_t point_count() const { return links_.size(); }

 private:
  const Scene& scene_;
  fem::SphereLinks links_;
  // Points outside this box (the blade's, blade frame, widened by a margin)
  // are outside the blade: no field query for them.
  Eigen::AlignedBox3d blade_box_;
  std::vector<Eigen::Vector3d> outside_;  // last position outside the blade, blade frame
  std::vector<bool> remembered_;
};

}  // namespace fahr::aist_bench
