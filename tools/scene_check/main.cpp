// fahr_scene_check: load a scene, report its problems or print the bodies and
// the run plan derived from it. Exit 0 when valid, 1 when not, 2 on misuse.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "fahr/scene/load_scene.h"
#include "fahr/scene/plan.h"
#include "fahr/scene/scene_error.h"

namespace {

void print_scene(const fahr::scene::Scene& scene) {
  using fahr::scene::to_string;
  std::cout << "scene " << scene.name << " (" << scene.source_name << ")\n"
            << "  mode " << to_string(scene.run.mode) << ", haptic " << scene.rates.haptic_hz
            << " Hz, fem " << scene.rates.fem_hz << " Hz, dds " << to_string(scene.dds.vendor)
            << " domain " << scene.dds.domain_id << "\n";
  for (const fahr::scene::Body& body : scene.bodies) {
    std::cout << "  body " << body.id << " " << body.name << ": " << to_string(body.role) << ", "
              << body.mesh_uri << " (" << to_string(body.mesh_unit) << ", scale " << body.mesh_scale
              << ")";
    if (body.deformable && body.deformable->fixed.node_indices_loaded) {
      std::cout << ", " << body.deformable->fixed.node_indices.size() << " fixed nodes";
    }
    std::cout << "\n";
  }
}

void print_plan(const fahr::scene::Scene& scene, const fahr::scene::ServicePlan& plan) {
  using fahr::scene::to_string;
  const auto yes_no = [](bool b) { return b ? "yes" : "no"; };
  std::cout << "plan\n  device gateway " << yes_no(plan.run_device_gateway) << ", haptic "
            << yes_no(plan.run_haptic) << ", fem " << yes_no(plan.run_fem) << ", lockstep clock "
            << yes_no(plan.run_lockstep_clock) << "\n";
  for (const fahr::scene::BodyPair& pair : plan.pairs) {
    std::cout << "  pair " << scene.bodies[pair.first].name << " / "
              << scene.bodies[pair.second].name << ": " << to_string(pair.kind) << " ("
              << to_string(pair.reason) << ")\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  fahr::scene::LoadOptions options;
  const char* path = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--no-file-check") == 0) {
      options.check_files = false;
    } else if (path == nullptr && argv[i][0] != '-') {
      path = argv[i];
    } else {
      path = nullptr;
      break;
    }
  }
  if (path == nullptr) {
    std::cerr << "usage: fahr_scene_check [--no-file-check] <scene.yaml>\n"
                 "  --no-file-check  do not require mesh, fixed-node and replay files\n";
    return 2;
  }
  try {
    const auto scene = fahr::scene::load_scene(path, options);
    print_scene(*scene);
    // Without the meshes' bounds every deformable/obstacle pair is kept.
    print_plan(*scene, fahr::scene::derive_plan(*scene));
  } catch (const fahr::scene::SceneError& error) {
    std::cerr << error.what() << "\n";
    return 1;
  }
  return 0;
}
