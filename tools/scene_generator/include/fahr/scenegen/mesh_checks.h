// Geometric checks on generated meshes: closedness, orientation, tet
// quality, point containment. Used by the generator (to refuse a bad scene),
// by the test and by the renderer's statistics.
#pragma once

#include <array>
#include <string>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

// Signed volume of a tet, positive for the orientation stated in MeshedSolid (mm^3).
double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Smallest of the six interior dihedral angles of a tet, in degrees.
double tet_min_dihedral_deg(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// 3 x inradius / circumradius of a tet: 1 for the regular tet, near 0 for
// slivers, caps and needles alike (the measure fahr::geometry reports).
double tet_radius_ratio(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Volume enclosed by a closed surface (mm^3); positive when outward oriented.
double enclosed_volume(const TriangleMesh& mesh);

// Two unit normals whose sum is shorter than this lie back to back; the same
// threshold as fahr::geometry's kFoldedNormalSum (this library must not
// depend on services/, so it is repeated here).
inline constexpr double kFoldedNormalSum = 1e-6;

struct ClosednessReport {
  int edge_count = 0;
  int bad_edges = 0;           // undirected edges not used by exactly two triangles
  int inconsistent_edges = 0;  // edges whose two triangles run them the same way
  int pinched_vertices = 0;    // vertices whose triangles form more than one fan
  int degenerate_triangles = 0;
  // Edges whose two triangles lie back to back (anti-parallel normals): the
  // surface folds onto itself with zero thickness there.
  int folded_edges = 0;
  // Smallest opening angle between the two triangles of an edge (180 = flat,
  // 0 = folded), over edges shared by exactly two non-degenerate triangles.
  double sharpest_edge_deg = 180.0;
  bool closed_and_oriented() const {
    return bad_edges == 0 && inconsistent_edges == 0 && pinched_vertices == 0;
  }
  // Closed, oriented, and usable for a signed distance: no folds, no zero-area triangles.
  bool clean() const {
    return closed_and_oriented() && folded_edges == 0 && degenerate_triangles == 0;
  }
};
ClosednessReport check_closed(const TriangleMesh& mesh);

// Generalised winding number of a closed surface around p: ~1 inside, ~0 outside.
double winding_number(const TriangleMesh& mesh, const Vec3& p);

// Distance (mm) from p to the nearest point of the surface.
double distance_to_surface(const TriangleMesh& mesh, const Vec3& p);

struct TetQuality {
  int tet_count = 0;
  double min_volume_mm3 = 0.0;
  double max_volume_mm3 = 0.0;
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  int below_10_deg = 0;  // tets whose smallest dihedral is under 10 degrees
  double min_radius_ratio = 0.0;
  int radius_ratio_below_0_1 = 0;
  int radius_ratio_below_0_3 = 0;
};
TetQuality tet_quality(const MeshedSolid& mesh);

// Each node's lumped mass (a quarter of each incident tet's volume) over the
// median node's.
std::vector<double> node_mass_over_median(const MeshedSolid& mesh);

// Axis-aligned bounds of a point set.
std::array<Vec3, 2> bounds(const std::vector<Vec3>& points);

}  // namespace fahr::scenegen
