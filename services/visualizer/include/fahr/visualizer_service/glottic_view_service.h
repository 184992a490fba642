// The glottic view as a service: at the scene's glottic_view.rate_hz it
// scores the newest FEM state and blade pose (libs/glottic_view), publishes
// fahr/GlotticView (live runs) and puts the sample into the visualizer's
// store, so the page, Foxglove clients and recordings all get the one
// value. In a replay it recomputes the view from the recorded geometry.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/glottic_view/scene_view.h"
#include "fahr/scene/scene.h"
#include "fahr/visualizer_service/live_state.h"

namespace fahr::visualizer_service {

class GlotticViewService {
 public:
  // `participant`: where to publish (null: only the store, e.g. a replay).
  // Throws std::invalid_argument (no glottic_view section, no tool) or
  // geometry::LoadError (a mesh) naming the file.
  GlotticViewService(const scene::Scene& scene, LiveState& live, common::Participant* participant);
  ~GlotticViewService();
  GlotticViewService(const GlotticViewService&) = delete;
  GlotticViewService& operator=(const GlotticViewService&) = delete;

  void start();
  void stop();

  // One view from the newest samples in the store; false when no FEM state
  // or ContactSet arrived since the last view (the same geometry, the same
  // view), when a soft body has no FEM state yet, or when it was refused
  // (non-finite, wrong node count). The thread calls it; tests call it
  // directly.
  bool update();

  struct Stats {
    std::uint64_t scored = 0;
    std::uint64_t refused = 0;  // states of the wrong size or not finite
    double last_percent = 0.0;
    double peak_force_n = 0.0;
  };
  Stats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace fahr::visualizer_service
