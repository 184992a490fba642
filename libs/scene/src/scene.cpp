#include "fahr/scene/scene.h"

#include <algorithm>
#include <cmath>

namespace fahr::scene {

namespace {

std::chrono::nanoseconds period_of(double hz) {
  return std::chrono::nanoseconds(std::llround(1.0e9 / hz));
}

}  // namespace

std::chrono::nanoseconds Rates::haptic_period() const {
  return period_of(haptic_hz);
}
std::chrono::nanoseconds Rates::fem_period() const {
  return period_of(fem_hz);
}
std::chrono::nanoseconds Rates::status_period() const {
  return period_of(status_hz);
}

std::optional<std::size_t> Scene::find_body(std::string_view body_name) const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == body_name) return i;
  }
  return std::nullopt;
}

std::optional<std::size_t> Scene::tool_index() const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].role == BodyRole::kTool) return i;
  }
  return std::nullopt;
}

std::size_t Scene::count(BodyRole role) const {
  return static_cast<std::size_t>(std::count_if(bodies.begin(), bodies.end(),
                                                [role](const Body& b) { return b.role == role; }));
}

}  // namespace fahr::scene
