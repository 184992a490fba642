// A small z-buffer rasterizer, orthographic or perspective: flat-shaded
// triangles, an optional half-space cut (to show a mid-sagittal section),
// supersampling, and an id per sample so a surface's visible samples can be
// counted. Enough to look at a scene honestly; not a viewer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scene_render {

using scenegen::Vec3;

struct Camera {
  Vec3 eye_direction;  // from the scene towards the viewer
  Vec3 up;
  Vec3 centre_mm;
  double width_mm;  // orthographic: visible width
  // Perspective instead: the eye at eye_mm looks at centre_mm with this
  // horizontal field of view; eye_direction and width_mm are then unused.
  bool perspective = false;
  Vec3 eye_mm = Vec3::Zero();
  double fov_deg = 30.0;
};

struct Cut {
  bool enabled = false;
  Vec3 normal = Vec3::UnitZ();  // fragments with (p - point) . normal > 0 are removed
  Vec3 point = Vec3::Zero();
};

class Rasterizer {
 public:
  Rasterizer(int width, int height, int supersample, const Camera& camera, const Cut& cut);

  // Draws a surface in `rgb` colour (0..1). Back faces (seen through the
  // cut) are drawn darker so a section reads as a section. `id` (>= 0) tags
  // the samples the surface wins in the depth test.
  void draw(const scenegen::TriangleMesh& mesh, const Vec3& rgb, int id = 0);

  // How many (supersampled) samples show the surface drawn with `id`.
  std::size_t count(int id) const;

  // Averages the supersamples into 8-bit RGB rows.
  std::vector<uint8_t> resolve() const;

 private:
  void draw_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& colour, int id);
  void fill(const Vec3 (&v)[3], const Vec3& lit, int id);
  // Screen position (x, y) and view depth of a point in front of the eye.
  Vec3 project(const Vec3& p) const;

  int width_, height_, ss_;
  int w_, h_;  // supersampled size
  Vec3 right_, up_, forward_;
  Camera camera_;
  Cut cut_;
  double pixels_per_mm_;
  std::vector<double> depth_;
  std::vector<Vec3> colour_;
  std::vector<int> id_;
  double focal_px_ = 0.0;  // perspective: pixels per unit of (lateral / depth)
};

}  // namespace fahr::scene_render
