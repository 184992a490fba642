// fahr_scene_render: renders the generated neonatal scene with a blade at its
// suggested poses into PNG pictures (side cutaways, front, oblique), so the
// scene can be looked at without any viewer.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "fahr/scenegen/blade_poses.h"
#include "fahr/scenegen/mesh_readers.h"
#include "png_writer.h"
#include "rasterizer.h"

namespace {

using fahr::scene_render::Camera;
using fahr::scene_render::Cut;
using fahr::scene_render::Rasterizer;
using fahr::scenegen::TriangleMesh;
using fahr::scenegen::Vec3;

constexpr int kWidthPx = 900;
constexpr int kHeightPx = 700;
constexpr int kSupersample = 3;

struct View {
  std::string file;
  std::string pose;
  Camera camera;
  bool cut;         // remove the patient's right half (z > 0) to show the mid-sagittal section
  bool show_blade;  // the front view leaves the blade out: its handle would hide the mouth
};

std::vector<View> views() {
  const Vec3 side(0.0, 0.0, 1.0);
  // The laryngoscopist's eye: on the line from the glottis out through the
  // mouth, above the supine neonate's head; the patient's anterior side is
  // up in the picture, as in a laryngoscopic view.
  const Vec3 sight = Vec3(0.876, 0.482, 0.0).normalized();
  const Vec3 anterior_up = (Vec3::UnitX() - sight.dot(Vec3::UnitX()) * sight).normalized();
  const Vec3 oblique = Vec3(0.8, 0.5, 1.0).normalized();
  const Vec3 up = Vec3::UnitY();
  return {
      {"scene_side.png", "initial", {side, up, Vec3(20.0, -30.0, 0.0), 210.0}, true, true},
      {"scene_side_closeup.png", "initial", {side, up, Vec3(-18.0, -18.0, 0.0), 100.0}, true, true},
      {"scene_front.png", "none", {Vec3::UnitX(), up, Vec3(0.0, -5.0, 0.0), 110.0}, false, false},
      {"scene_oblique.png", "initial", {oblique, up, Vec3(0.0, -20.0, 0.0), 190.0}, true, true},
      {"scene_airway_side.png", "none", {side, up, Vec3(-38.0, -28.0, 0.0), 110.0}, true, false},
      {"scene_laryngoscopist.png",
       "none",
       {sight, anterior_up, Vec3(-30.0, -15.0, 0.0), 60.0},
       false,
       false},
      {"scene_side_pressing.png",
       "pressing",
       {side, up, Vec3(-15.0, -18.0, 0.0), 110.0},
       true,
       true},
      {"scene_oblique_pressing.png",
       "pressing",
       {oblique, up, Vec3(-10.0, -20.0, 0.0), 150.0},
       true,
       true},
  };
}

TriangleMesh tongue_surface(const fahr::scenegen::MeshedSolid& tet) {
  return {tet.nodes, tet.boundary};
}

}  // namespace

int main(int argc, char** argv) {
  std::string mesh_dir = "meshes/neonatal";
  std::string out_dir;
  std::string blade = "miller0";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--meshes") {
      mesh_dir = argv[i + 1];
    } else if (flag == "--out") {
      out_dir = argv[i + 1];
    } else if (flag == "--blade") {
      blade = argv[i + 1];
    } else {
      std::fprintf(
          stderr,
          "usage: fahr_scene_render [--meshes DIR] [--out DIR] [--blade miller0|miller1]\n");
      return 2;
    }
  }
  if (out_dir.empty()) out_dir = mesh_dir;

  std::string error;
  fahr::scenegen::MeshedSolid tongue;
  if (!fahr::scenegen::read_tetgen(mesh_dir + "/tongue", tongue, error)) {
    std::fprintf(stderr, "fahr_scene_render: %s\n", error.c_str());
    return 1;
  }
  // Colours: tissue pink, bone ivory, skin, airway blue (as in the paper's
  // figures, where the trachea is blue), steel.
  const std::vector<std::pair<std::string, Vec3>> rigid = {
      {"palate", Vec3(0.93, 0.88, 0.74)},         {"jaw", Vec3(0.90, 0.85, 0.70)},
      {"hyoid", Vec3(0.88, 0.82, 0.62)},          {"lips_face", Vec3(0.96, 0.76, 0.66)},
      {"larynx_trachea", Vec3(0.45, 0.60, 0.90)}, {"epiglottis", Vec3(0.98, 0.86, 0.55)},
      {"soft_palate", Vec3(0.90, 0.56, 0.60)},    {"pharynx", Vec3(0.72, 0.52, 0.56)}};
  std::map<std::string, TriangleMesh> meshes;
  for (const auto& [name, colour] : rigid) {
    const std::string path = std::string(mesh_dir).append("/").append(name).append(".obj");
    if (!fahr::scenegen::read_obj(path, meshes[name], error)) {
      std::fprintf(stderr, "fahr_scene_render: %s\n", error.c_str());
      return 1;
    }
  }
  TriangleMesh tool;
  if (!fahr::scenegen::read_obj(mesh_dir + "/" + blade + ".obj", tool, error)) {
    std::fprintf(stderr, "fahr_scene_render: %s\n", error.c_str());
    return 1;
  }
  std::map<std::string, fahr::scenegen::BladePose> poses;
  for (const auto& p : fahr::scenegen::suggested_blade_poses()) poses[p.name] = p;

  const TriangleMesh tongue_mesh = tongue_surface(tongue);
  for (const auto& view : views()) {
    Cut cut;
    cut.enabled = view.cut;
    Rasterizer r(kWidthPx, kHeightPx, kSupersample, view.camera, cut);
    for (const auto& [name, colour] : rigid) r.draw(meshes[name], colour);
    r.draw(tongue_mesh, Vec3(0.85, 0.38, 0.42));
    if (view.show_blade) {
      r.draw(fahr::scenegen::transformed(tool, poses.at(view.pose)), Vec3(0.72, 0.74, 0.78));
    }
    const std::string path = out_dir + "/" + view.file;
    if (!fahr::scene_render::write_png(path, kWidthPx, kHeightPx, r.resolve(), error)) {
      std::fprintf(stderr, "fahr_scene_render: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s (blade pose: %s)\n", path.c_str(), view.pose.c_str());
  }
  return 0;
}
