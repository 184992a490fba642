// libFuzzer entry for the TetGen loader. The input holds the .node, .ele and
// (optional) .face texts separated by lines "===".
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fahr/geometry/load_error.h"
#include "fahr/geometry/tetgen_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "\n===\n";
  const std::size_t first = input.find(kSeparator);
  if (first == std::string_view::npos) {
    return 0;
  }
  const std::string_view node = input.substr(0, first);
  std::string_view rest = input.substr(first + kSeparator.size());
  const std::size_t second = rest.find(kSeparator);
  const std::string_view ele = rest.substr(0, second);
  const std::string_view face = second == std::string_view::npos
                                    ? std::string_view()
                                    : rest.substr(second + kSeparator.size());
  try {
    const fahr::geometry::TetMesh mesh = fahr::geometry::parse_tetgen(
        {node, "fuzz.node"}, {ele, "fuzz.ele"}, {face, "fuzz.face"}, 0.001);
    (void)mesh.boundary_surface();
  } catch (const fahr::geometry::LoadError&) {
    // Rejected input is the expected outcome; crashes and sanitizer reports are the findings.
  }
  return 0;
}
