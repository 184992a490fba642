// Sphere layout -> FEM sphere links.
#include "fahr/layout_links/fem_links.h"

#include <stdexcept>
#include <string>

namespace fahr::layout_links {

fem::SphereLinks to_fem_links(const sphere_layout::SphereLayout& layout, double skin_m) {
  fem::SphereLinks links;
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const std::string error = links.add_sphere(layout.nodes(i), layout.weights(i),
                                               layout.sphere(i).rest_radius_m + skin_m);
    if (!error.empty()) throw std::invalid_argument("sphere links: " + error);
  }
  return links;
}

}  // namespace fahr::layout_links
