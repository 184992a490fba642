// Orthographic or perspective rasterizer with per-fragment cut, flat
// Lambert shading and sample ids.
#include "rasterizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::scene_render {
namespace {

constexpr double kAmbient = 0.45;
constexpr double kDiffuse = 0.55;
constexpr double kBackFaceShade = 0.6;  // inner faces seen through the cut
constexpr double kNearMm = 0.05;        // perspective: nothing closer to the eye is drawn
constexpr double kPi = 3.14159265358979323846;

}  // namespace

Rasterizer::Rasterizer(int width, int height, int supersample, const Camera& camera, const Cut& cut)
    : width_(width),
      height_(height),
      ss_(supersample),
      w_(width * supersample),
      h_(height * supersample),
      camera_(camera),
      cut_(cut) {
  forward_ = camera.perspective ? Vec3((camera.centre_mm - camera.eye_mm).normalized())
                                : Vec3(-camera.eye_direction.normalized());
  right_ = forward_.cross(camera.up).normalized();
  up_ = right_.cross(forward_);
  pixels_per_mm_ = w_ / camera.width_mm;
  focal_px_ = 0.5 * w_ / std::tan(0.5 * camera.fov_deg * kPi / 180.0);
  const auto samples = static_cast<size_t>(w_) * static_cast<size_t>(h_);
  depth_.assign(samples, std::numeric_limits<double>::infinity());
  colour_.assign(samples, Vec3(1.0, 1.0, 1.0));
  id_.assign(samples, -1);
}

void Rasterizer::draw(const scenegen::TriangleMesh& mesh, const Vec3& rgb, int id) {
  for (const auto& t : mesh.triangles) {
    draw_triangle(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], rgb, id);
  }
}

std::size_t Rasterizer::count(int id) const {
  return static_cast<std::size_t>(std::count(id_.begin(), id_.end(), id));
}

Vec3 Rasterizer::project(const Vec3& p) const {
  if (camera_.perspective) {
    const Vec3 d = p - camera_.eye_mm;
    const double z = d.dot(forward_);
    return {0.5 * w_ + focal_px_ * d.dot(right_) / z, 0.5 * h_ - focal_px_ * d.dot(up_) / z, z};
  }
  const Vec3 d = p - camera_.centre_mm;
  return {0.5 * w_ + d.dot(right_) * pixels_per_mm_, 0.5 * h_ - d.dot(up_) * pixels_per_mm_,
          d.dot(forward_)};
}

void Rasterizer::draw_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& colour,
                               int id) {
  const Vec3 normal = (b - a).cross(c - a);
  if (normal.norm() <= 0.0) return;
  const Vec3 n = normal.normalized();
  const double facing = -n.dot(forward_);  // > 0: front face
  // Light from over the viewer's right shoulder, fixed to the camera.
  const Vec3 light = (camera_.eye_direction.normalized() + 0.4 * up_ + 0.3 * right_).normalized();
  double shade = kAmbient + kDiffuse * std::abs(n.dot(light));
  if (facing < 0.0) shade *= kBackFaceShade;
  const Vec3 lit = colour * shade;

  if (!camera_.perspective) {
    const Vec3 v[3] = {a, b, c};
    fill(v, lit, id);
    return;
  }
  // Perspective: clip against the near plane (a polygon of up to four
  // corners), then fill it as a fan.
  const Vec3 in[3] = {a, b, c};
  Vec3 poly[4];
  int corners = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3& p = in[i];
    const Vec3& q = in[(i + 1) % 3];
    const double dp = (p - camera_.eye_mm).dot(forward_) - kNearMm;
    const double dq = (q - camera_.eye_mm).dot(forward_) - kNearMm;
    if (dp >= 0.0) poly[corners++] = p;
    if ((dp >= 0.0) != (dq >= 0.0)) poly[corners++] = p + (q - p) * (dp / (dp - dq));
  }
  for (int i = 1; i + 1 < corners; ++i) {
    const Vec3 v[3] = {poly[0], poly[i], poly[i + 1]};
    fill(v, lit, id);
  }
}

void Rasterizer::fill(const Vec3 (&v)[3], const Vec3& lit, int id) {
  double sx[3], sy[3], sz[3];
  for (int i = 0; i < 3; ++i) {
    const Vec3 s = project(v[i]);
    sx[i] = s.x();
    sy[i] = s.y();
    sz[i] = s.z();
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
      double w0 = ((sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py)) / area;
      double w1 = ((sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py)) / area;
      double w2 = 1.0 - w0 - w1;
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      double z = w0 * sz[0] + w1 * sz[1] + w2 * sz[2];
      if (camera_.perspective) {
        // Depth is not linear on the screen, its inverse is.
        const double inverse = w0 / sz[0] + w1 / sz[1] + w2 / sz[2];
        z = 1.0 / inverse;
        w0 *= z / sz[0];
        w1 *= z / sz[1];
        w2 = 1.0 - w0 - w1;
      }
      const int pixel = y * w_ + x;
      const auto k = static_cast<size_t>(pixel);
      if (z >= depth_[k]) continue;
      if (cut_.enabled) {
        const Vec3 p = w0 * v[0] + w1 * v[1] + w2 * v[2];
        if ((p - cut_.point).dot(cut_.normal) > 0.0) continue;
      }
      depth_[k] = z;
      colour_[k] = lit;
      id_[k] = id;
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
