// Surface loader through assimp: OBJ, STL (per-face normals, so vertices must be
// welded), PLY; units; errors name the file.
#include "fahr/geometry/surface_loader.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>

#include "test_support.h"

namespace fahr::geometry {
namespace {

constexpr double kMm = 0.001;

std::string num(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

std::string obj_text(const SurfaceMesh& mesh, double unit_m) {
  std::ostringstream out;
  for (const auto& v : mesh.vertices()) {
    out << "v " << num(v.x() / unit_m) << " " << num(v.y() / unit_m) << " " << num(v.z() / unit_m)
        << "\n";
  }
  for (const auto& t : mesh.triangles()) {
    out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  }
  return out.str();
}

std::string stl_text(const SurfaceMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "solid test\n";
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const auto& n = mesh.face_normals()[f];
    out << "facet normal " << num(n.x()) << " " << num(n.y()) << " " << num(n.z())
        << "\nouter loop\n";
    for (Index v : mesh.triangles()[f]) {
      const auto& x = mesh.vertices()[v];
      out << "vertex " << num(x.x() / unit_m) << " " << num(x.y() / unit_m) << " "
          << num(x.z() / unit_m) << "\n";
    }
    out << "endloop\nendfacet\n";
  }
  out << "endsolid test\n";
  return out.str();
}

std::string ply_text(const SurfaceMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\nelement vertex " << mesh.vertex_count()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
      << mesh.triangle_count() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : mesh.vertices()) {
    out << num(v.x() / unit_m) << " " << num(v.y() / unit_m) << " " << num(v.z() / unit_m) << "\n";
  }
  for (const auto& t : mesh.triangles()) {
    out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  }
  return out.str();
}

// assimp keeps positions in float32: relative rounding 6e-8 per coordinate,
// so volumes agree to a few 1e-7 at best.
constexpr double kFloat32VolumeRelative = 1e-6;

void expect_closed_sphere(const SurfaceMesh& loaded, const SurfaceMesh& reference) {
  EXPECT_EQ(loaded.vertex_count(), reference.vertex_count());
  EXPECT_EQ(loaded.triangle_count(), reference.triangle_count());
  EXPECT_TRUE(loaded.is_closed());
  EXPECT_TRUE(loaded.is_manifold());
  EXPECT_NEAR(loaded.enclosed_volume_m3(), reference.enclosed_volume_m3(),
              kFloat32VolumeRelative * reference.enclosed_volume_m3());
}

TEST(SurfaceLoader, ObjStlPlyInMillimetres) {
  const SurfaceMesh sphere = test::icosphere(2, 0.01);
  test::TempDir dir;
  expect_closed_sphere(load_surface(dir.write("s.obj", obj_text(sphere, kMm)), kMm), sphere);
  expect_closed_sphere(load_surface(dir.write("s.stl", stl_text(sphere, kMm)), kMm), sphere);
  expect_closed_sphere(load_surface(dir.write("s.ply", ply_text(sphere, kMm)), kMm), sphere);
}

TEST(SurfaceLoader, ErrorsNameTheFile) {
  test::TempDir dir;
  const auto missing = dir.path() / "missing.obj";
  test::expect_load_error([&] { load_surface(missing, 1.0); }, missing.string(), 0,
                          {"cannot open"});
  const auto garbage = dir.write("garbage.stl", "this is not a mesh\n");
  test::expect_load_error([&] { load_surface(garbage, 1.0); }, garbage.string(), 0, {});
}

}  // namespace
}  // namespace fahr::geometry
