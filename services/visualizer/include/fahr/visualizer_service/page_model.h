// What the page is sent: the newest samples decoded (Fast DDS type
// support, common/cdr_bytes.h) and turned into compact frames, built once
// per display tick and shared by every page client.
//   scene frame (binary): a body's rest vertices (float32) and triangles
//     (uint32); rigid bodies from the scene's surface meshes, the deformable
//     one from its SceneDescription (with its AIST spheres).
//   deformation frame (binary): the deformed vertices (float32) and, per
//     node, the largest principal Green strain over the tets around it,
//     computed with the FEM's own definition (fem/strain.h).
//   state frame (JSON, small): device and proxy poses, lost track, force and
//     limit, contacts, rates and latency.
// Layouts: docs/design/visualizer.md.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fahr/fem/element_rest.h"
#include "fahr/scene/scene.h"
#include "fahr/visualizer_service/live_state.h"

namespace fahr::visualizer_service {

struct Frame {
  bool binary = false;
  // Never dropped for a slow client: without it the page cannot draw
  // (scene meshes, hello, advertise).
  bool sticky = false;
  std::uint64_t version = 0;
  std::string data;
};
using FramePtr = std::shared_ptr<const Frame>;

// Frame kinds (the first uint32 of a binary frame).
inline constexpr std::uint32_t kSceneFrame = 1;
inline constexpr std::uint32_t kDeformationFrame = 2;

// Stream ids: one newest frame each; a client is sent a stream's frame when
// its version is newer than the one it has.
inline constexpr int kStateStream = 1;
inline constexpr int kSceneStreamBase = 1000;    // + body id
inline constexpr int kDeformStreamBase = 20000;  // + body id (body ids < 10^4 in practice)

class PageModel {
 public:
  // `scene`: where the rigid bodies' surface meshes come from (may be null:
  // then only the deformable body, from its SceneDescription, is drawn).
  explicit PageModel(std::shared_ptr<const scene::Scene> scene);

  // Takes the slots that changed since the last call (LiveState::collect's
  // output) and rebuilds the frames they touch. `mode` is "live" or "replay".
  void update(const std::vector<Slot>& slots, const std::string& mode);

  const std::map<int, FramePtr>& frames() const { return frames_; }

  // For tests: the newest deformation's largest node strain.
  double max_node_strain() const { return max_node_strain_; }

 private:
  struct Deformable {
    std::uint32_t body_id = 0;
    fem::ElementRest rest;
    std::vector<std::vector<std::uint32_t>> node_tets;
    std::size_t nodes = 0;
  };
  void add_rigid_bodies();
  void on_scene(const Slot& slot);
  void on_deformation(const Slot& slot);
  void build_state(const std::string& mode);
  FramePtr make(int stream, bool binary, bool sticky, std::string data);

  std::shared_ptr<const scene::Scene> scene_;
  std::map<int, FramePtr> frames_;
  std::map<std::uint32_t, Deformable> deformables_;
  std::vector<std::uint64_t> seen_;  // slot versions already used
  std::uint64_t next_version_ = 1;
  // Scratch, kept between updates.
  std::vector<double> positions_;
  std::vector<double> tet_strain_;
  double max_node_strain_ = 0;
  // The newest decoded small samples' JSON pieces, by slot index.
  std::map<std::size_t, std::pair<std::size_t, std::string>> pieces_;
  bool state_dirty_ = false;
};

}  // namespace fahr::visualizer_service
