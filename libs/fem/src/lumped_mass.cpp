// Row-sum lumping of the consistent mass of linear tetrahedra, which for
// linear tets equals an equal split of rho V over the four nodes.
#include "fahr/fem/lumped_mass.h"

namespace fahr::fem {

std::vector<double> lumped_mass(const ElementRest& rest, std::size_t node_count,
                                double density_kg_per_m3) {
  std::vector<double> mass(node_count, 0.0);
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const double quarter = 0.25 * density_kg_per_m3 * rest.volume_m3[e];
    for (const std::uint32_t node : rest.tets[e]) mass[node] += quarter;
  }
  return mass;
}

}  // namespace fahr::fem
