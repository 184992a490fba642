// Tetrahedral mesher for an implicit solid: a regular cube grid, each cube
// split into the six Kuhn (Freudenthal) tets around its main diagonal, which
// is conforming across all cubes; tets whose centroid is inside are kept, then
// boundary nodes are pulled onto the implicit surface, each move shortened or
// refused when it would invert a tet or push it below the quality floor;
// the tets of nodes left far lighter than the median node are then peeled
// off and the rest snapped again.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/implicit_solid.h"

namespace fahr::scenegen {

struct TetMesherSettings {
  double cell_mm = 2.0;
  double min_dihedral_deg = 8.0;     // snapping keeps every touched tet above this
  double min_volume_fraction = 0.1;  // ... and above this fraction of a grid tet's volume
  int snap_passes = 3;
  // Rounds of interior smoothing, each followed by the snap passes again.
  int smoothing_rounds = 2;
  // After snapping, the tets of a node lighter than this fraction of the
  // median node are peeled off and the rest snapped again, for at most
  // `peel_rounds` rounds.
  double min_node_mass_fraction = 0.1;
  int peel_rounds = 4;
  // The grid turned about z by this angle (a plane of the solid can then lie
  // along grid faces), and optionally one grid level put on y = this value
  // in the turned frame.
  double grid_turn_z_deg = 0.0;
  std::optional<double> grid_level_y_mm;
};

struct TetMesherReport {
  int grid_cells = 0;
  int boundary_nodes = 0;
  int snapped_fully = 0;
  int snapped_partly = 0;
  int not_snapped = 0;
  double max_surface_gap_mm = 0.0;  // |implicit value| at boundary nodes after snapping
  int nonmanifold_boundary_edges = 0;
  int peeled_tets = 0;  // tets peeled off around light nodes
  int light_nodes = 0;  // light nodes left after the last round
};

// The faces that belong to one tet only, outward for positively oriented
// tets, in tet order.
std::vector<std::array<int, 3>> boundary_faces(const std::vector<std::array<int, 4>>& tets);

MeshedSolid mesh_implicit_solid(const ImplicitSolid& shape, const TetMesherSettings& settings,
                                TetMesherReport& report);

}  // namespace fahr::scenegen
