// A small orthographic z-buffer rasterizer: flat-shaded triangles, an
// optional half-space cut (to show a mid-sagittal section) and
// supersampling. Enough to look at a scene honestly; not a viewer.
#pragma once

#include <cstdint>
#include <vector>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scene_render {

using scenegen::Vec3;

struct Camera {
  Vec3 eye_direction;  // from the scene towards the viewer
  Vec3 up;
  Vec3 centre_mm;
  double width_mm;  // visible width
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
  // cut) are drawn darker so a section reads as a section.
  void draw(const scenegen::TriangleMesh& mesh, const Vec3& rgb);

  // Averages the supersamples into 8-bit RGB rows.
  std::vector<uint8_t> resolve() const;

 private:
  void draw_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& colour);

  int width_, height_, ss_;
  int w_, h_;  // supersampled size
  Vec3 right_, up_, forward_;
  Camera camera_;
  Cut cut_;
  double pixels_per_mm_;
  std::vector<double> depth_;
  std::vector<Vec3> colour_;
};

}  // namespace fahr::scene_render
