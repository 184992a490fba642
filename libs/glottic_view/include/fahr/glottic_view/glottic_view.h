// The glottic view score: the share of the glottic opening an eye sees past
// the anatomy, the deformed soft tissue and the laryngoscope (the percentage
// of glottic opening, POGO, that trainers grade laryngoscopy by: Levitan et
// al., Acad Emerg Med 1998;5:919).
//
// The opening is an ellipse (a disc when its two radii are equal: the glottic
// slit is long from front to back and narrow across). Its area is sampled by
// a sunflower pattern; each
// sample is seen when the segment from the eye to it crosses no occluding
// triangle, and counts with the solid angle its patch of disc subtends at the
// eye (cos(normal, sight) / distance^2), so the score is the visible share
// of the opening's *image*, the quantity a pixel count of a rendered view
// measures. A disc seen edge-on or from behind scores 0.
//
// Occluders: rigid surfaces in the world frame (built once), the tool's
// surface in its own frame (the eye rides with it), and deformable bodies'
// boundary triangles at positions given per score. Not for the 1 kHz tick: a
// score of 1,024 samples against the neonatal scene takes about a
// millisecond and rebuilds the deformable bodies' trees.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "fahr/geometry/mesh_types.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/triangle_bvh.h"

namespace fahr::glottic_view {

struct Opening {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();   // unit; out of the airway, towards the eye
  double radius_m = 0.0;  // along major_axis (the disc's radius when minor_radius_m is 0)
  // An ellipse: the direction of radius_m (in the opening's plane; its part
  // along the normal is removed) and the radius across it, (0, radius_m].
  // A zero minor radius makes the opening a disc and major_axis unused.
  Eigen::Vector3d major_axis = Eigen::Vector3d::Zero();
  double minor_radius_m = 0.0;
};

// The opening's point at (x, y) of the unit disc: x along the major axis
// (any direction in the plane for a disc), y across it. For an opening as
// GlotticView::opening() gives it (unit normal, major axis in its plane).
Eigen::Vector3d opening_point(const Opening& opening, double x, double y);

struct ViewScore {
  double visible_share = 0.0;  // [0, 1]: the POGO score / 100
  std::size_t samples = 0;     // samples facing the eye
  std::size_t visible = 0;     // of those, seen
  bool facing = false;         // the eye is on the opening's open side
};

class GlotticView {
 public:
  // Throws std::invalid_argument on a non-positive radius, a zero normal, a
  // minor radius above the radius or with no major axis in the opening's
  // plane, or fewer than 16 samples.
  explicit GlotticView(const Opening& opening, std::size_t samples = 1024);

  // A rigid occluder, world frame (m).
  void add_rigid(const geometry::SurfaceMesh& surface_world);
  // The tool's surface in its own frame (m); replaces any earlier one.
  void set_tool(const geometry::SurfaceMesh& surface_tool_frame);
  // A deformable occluder's boundary triangles (indices into its node
  // positions); returns its index for score(). Throws std::invalid_argument
  // on a negative index.
  std::size_t add_deformable(std::vector<geometry::Triangle> boundary);

  // The score seen from `eye_world`. `world_from_tool`: where the tool is
  // (absent: no tool in the view). `deformable_positions[i]`: body i's node
  // positions, world frame, m; each span must cover every index of its
  // boundary and be finite (std::invalid_argument otherwise). Fewer spans
  // than bodies leave the rest out of the view.
  ViewScore score(const Eigen::Vector3d& eye_world,
                  const std::optional<Eigen::Isometry3d>& world_from_tool,
                  std::span<const std::span<const Eigen::Vector3d>> deformable_positions);

  const Opening& opening() const { return opening_; }
  // The sample points on the opening, world frame (for tests and pictures).
  const std::vector<Eigen::Vector3d>& sample_points() const { return points_; }

 private:
  Opening opening_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<geometry::TriangleBvh> rigid_;
  std::optional<geometry::TriangleBvh> tool_;
  std::vector<std::vector<geometry::Triangle>> deformable_boundaries_;
};

}  // namespace fahr::glottic_view
