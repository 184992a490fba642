// Orthographic rasterizer with per-fragment cut and flat Lambert shading.
#include "rasterizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::scene_render {
namespace {

constexpr double kAmbient = 0.45;
constexpr double kDiffuse = 0.55;
constexpr double kBackFaceShade = 0.6;  // inner faces seen through the cut

}  // namespace

Rasterizer::Rasterizer(int width, int height, int supersample, const Camera& camera, const Cut& cut)
    : width_(width),
      height_(height),
      ss_(supersample),
      w_(width * supersample),
      h_(height * supersample),
      camera_(camera),
      cut_(cut) {
  forward_ = -camera.eye_direction.normalized();
  right_ = forward_.cross(camera.up).normalized();
  up_ = right_.cross(forward_);
  pixels_per_mm_ = w_ / camera.width_mm;
  depth_.assign(static_cast<size_t>(w_) * static_cast<size_t>(h_),
                std::numeric_limits<double>::infinity());
  colour_.assign(static_cast<size_t>(w_) * static_cast<size_t>(h_), Vec3(1.0, 1.0, 1.0));
}

void Rasterizer::draw(const scenegen::TriangleMesh& mesh, const Vec3& rgb) {
  for (const auto& t : mesh.triangles) {
    draw_triangle(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], rgb);
  }
}

void Rasterizer::draw_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& colour) {
  const Vec3 normal = (b - a).cross(c - a);
  if (normal.norm() <= 0.0) return;
  const Vec3 n = normal.normalized();
  const double facing = -n.dot(forward_);  // > 0: front face
  // Light from over the viewer's right shoulder, fixed to the camera.
  const Vec3 light = (camera_.eye_direction.normalized() + 0.4 * up_ + 0.3 * right_).normalized();
  double shade = kAmbient + kDiffuse * std::abs(n.dot(light));
  if (facing < 0.0) shade *= kBackFaceShade;
  const Vec3 lit = colour * shade;

  const Vec3 v[3] = {a, b, c};
  double sx[3], sy[3], sz[3];
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = v[i] - camera_.centre_mm;
    sx[i] = 0.5 * w_ + d.dot(right_) * pixels_per_mm_;
    sy[i] = 0.5 * h_ - d.dot(up_) * pixels_per_mm_;
    sz[i] = d.dot(forward_);
  }
  const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
  const int x1 = std::min(w_ - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({sy[0], sy[1], sy[2]}))));
  const int y1 = std::min(h_ - 1, static_cast<int>(std::ceil(std::max({sy[0], sy[1], sy[2]}))));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      const double py = y + 0.5;
      const double w0 = ((sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py)) / area;
      const double w1 = ((sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py)) / area;
      const double w2 = 1.0 - w0 - w1;
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      const double z = w0 * sz[0] + w1 * sz[1] + w2 * sz[2];
      const int pixel = y * w_ + x;
      const auto k = static_cast<size_t>(pixel);
      if (z >= depth_[k]) continue;
      if (cut_.enabled) {
        const Vec3 p = w0 * a + w1 * b + w2 * c;
        if ((p - cut_.point).dot(cut_.normal) > 0.0) continue;
      }
      depth_[k] = z;
      colour_[k] = lit;
    }
  }
}

std::vector<uint8_t> Rasterizer::resolve() const {
  std::vector<uint8_t> rgb(static_cast<size_t>(width_ * height_ * 3));
  const double samples = static_cast<double>(ss_ * ss_);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      Vec3 sum = Vec3::Zero();
      for (int j = 0; j < ss_; ++j) {
        for (int i = 0; i < ss_; ++i) {
          const int sample = (y * ss_ + j) * w_ + x * ss_ + i;
          sum += colour_[static_cast<size_t>(sample)];
        }
      }
      const Vec3 c = (sum / samples).cwiseMax(0.0).cwiseMin(1.0) * 255.0;
      for (int ch = 0; ch < 3; ++ch) {
        const int byte = (y * width_ + x) * 3 + ch;
        rgb[static_cast<size_t>(byte)] = static_cast<uint8_t>(std::lround(c[ch]));
      }
    }
  }
  return rgb;
}

}  // namespace fahr::scene_render
