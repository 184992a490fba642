// libFuzzer entry for the Gmsh loader: the input is one file's text.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fahr/geometry/gmsh_loader.h"
#include "fahr/geometry/load_error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const fahr::geometry::TetMesh mesh = fahr::geometry::parse_gmsh({text, "fuzz.msh"}, 0.001);
    (void)mesh.boundary_surface();
  } catch (const fahr::geometry::LoadError&) {
    // Rejected input is the expected outcome; crashes and sanitizer reports are the findings.
  }
  return 0;
}
