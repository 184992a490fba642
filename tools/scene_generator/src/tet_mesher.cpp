// Kuhn-grid tet mesher with quality-guarded boundary snapping.
#include "fahr/scenegen/tet_mesher.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "fahr/scenegen/mesh_checks.h"

namespace fahr::scenegen {
namespace {

// The six axis orders of the Kuhn split: a tet walks from corner (0,0,0) to
// (1,1,1) adding one unit axis at a time in this order. Every cube uses the
// same main diagonal, so shared faces are split identically (conforming).
constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

// Faces of a positively oriented tet (a, b, c, d), outward.
constexpr int kTetFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

std::array<int, 3> sorted_face(const std::array<int, 4>& t, int f) {
  std::array<int, 3> k{t[kTetFaces[f][0]], t[kTetFaces[f][1]], t[kTetFaces[f][2]]};
  std::sort(k.begin(), k.end());
  return k;
}

// The cube grid, turned about z by `turn` (grid frame to head frame).
struct Grid {
  Vec3 origin;  // in the grid frame
  double h;
  int nx, ny, nz;
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  int node(int i, int j, int k) const { return (i * (ny + 1) + j) * (nz + 1) + k; }
  Vec3 position(int i, int j, int k) const { return turn * (origin + h * Vec3(i, j, k)); }
};

Grid make_grid(const ImplicitSolid& shape, const TetMesherSettings& settings) {
  const double h = settings.cell_mm;
  Grid g{Vec3::Zero(), h, 0, 0, 0};
  g.turn =
      Eigen::AngleAxisd(settings.grid_turn_z_deg * 3.14159265358979323846 / 180.0, Vec3::UnitZ())
          .toRotationMatrix();
  // The shape's box in the grid frame, with one spare cell on every side so
  // the surface never touches the grid edge.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 c((corner & 1) ? shape.upper_bound().x() : shape.lower_bound().x(),
                 (corner & 2) ? shape.upper_bound().y() : shape.lower_bound().y(),
                 (corner & 4) ? shape.upper_bound().z() : shape.lower_bound().z());
    const Vec3 local = g.turn.transpose() * c;
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  lo -= Vec3::Constant(h);
  hi += Vec3::Constant(h);
  if (settings.grid_level_y_mm) {
    // Put a grid level on the requested plane (y in the grid frame).
    lo.y() = *settings.grid_level_y_mm - h * std::ceil((*settings.grid_level_y_mm - lo.y()) / h);
  }
  g.origin = lo;
  g.nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / h));
  g.ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / h));
  g.nz = static_cast<int>(std::ceil((hi.z() - lo.z()) / h));
  // Centre the grid on z = 0 so the mesh is mirror symmetric about the mid-sagittal plane.
  g.nz += g.nz % 2;
  g.origin.z() = -0.5 * g.nz * h;
  return g;
}

// Tets whose centroid is inside the solid, indices into the full grid.
std::vector<std::array<int, 4>> inside_tets(const ImplicitSolid& shape, const Grid& g) {
  std::vector<std::array<int, 4>> tets;
  for (int i = 0; i < g.nx; ++i) {
    for (int j = 0; j < g.ny; ++j) {
      for (int k = 0; k < g.nz; ++k) {
        for (const auto& order : kAxisOrders) {
          int c[3] = {i, j, k};
          std::array<int, 4> t{};
          std::array<Vec3, 4> p;
          for (int v = 0; v < 4; ++v) {
            if (v > 0) ++c[order[v - 1]];
            t[v] = g.node(c[0], c[1], c[2]);
            p[v] = g.position(c[0], c[1], c[2]);
          }
          const Vec3 centroid = 0.25 * (p[0] + p[1] + p[2] + p[3]);
          if (shape.value(centroid) >= 0.0) continue;
          if (tet_signed_volume(p[0], p[1], p[2], p[3]) < 0.0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
      }
    }
  }
  return tets;
}

// Tets kept by their centroid can meet along an edge only (four boundary
// faces around one edge): the boundary is then not a manifold. Removing the
// tets on such edges settles it in a pass or two.
void remove_nonmanifold_edges(std::vector<std::array<int, 4>>& tets) {
  constexpr int kMaxPasses = 10;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    std::map<std::pair<int, int>, int> edge_uses;
    for (const auto& f : boundary_faces(tets)) {
      for (int k = 0; k < 3; ++k) ++edge_uses[std::minmax(f[k], f[(k + 1) % 3])];
    }
    std::vector<std::pair<int, int>> bad;
    for (const auto& [edge, uses] : edge_uses) {
      if (uses != 2) bad.push_back(edge);
    }
    if (bad.empty()) return;
    std::vector<std::array<int, 4>> kept;
    for (const auto& t : tets) {
      bool on_bad_edge = false;
      for (const auto& [a, b] : bad) {
        const bool has_a = std::find(t.begin(), t.end(), a) != t.end();
        const bool has_b = std::find(t.begin(), t.end(), b) != t.end();
        on_bad_edge = on_bad_edge || (has_a && has_b);
      }
      if (!on_bad_edge) kept.push_back(t);
    }
    tets.swap(kept);
  }
}

// Number of fans the boundary triangles around each vertex form (1 on a
// manifold surface).
std::map<int, int> boundary_fans(const std::vector<std::array<int, 3>>& faces) {
  std::map<int, std::vector<std::pair<int, int>>> spokes;  // vertex -> (edge end, face)
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      spokes[faces[f][k]].push_back({faces[f][(k + 1) % 3], static_cast<int>(f)});
      spokes[faces[f][k]].push_back({faces[f][(k + 2) % 3], static_cast<int>(f)});
    }
  }
  std::map<int, int> fans;
  for (const auto& [v, around] : spokes) {
    std::map<int, int> parent;
    const auto find = [&parent](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    for (const auto& [end, f] : around) parent[f] = f;
    std::map<int, int> first_at_end;
    for (const auto& [end, f] : around) {
      const auto [it, inserted] = first_at_end.emplace(end, f);
      if (!inserted) parent[find(f)] = find(it->second);
    }
    int count = 0;
    for (const auto& [f, up] : parent) count += find(f) == f ? 1 : 0;
    fans[v] = count;
  }
  return fans;
}

// Tets that touch only at a vertex (two cones of tets meeting at a point,
// where the tongue nearly touches the floor beside it) leave a boundary that
// is not a manifold at that vertex. Around such a vertex the incident tets
// are grouped by the faces they share through it and all but the largest
// group are removed; when they form one group (the outside touches itself
// there instead) all of them go. Alternates with the edge pass until both
// hold.
bool remove_pinched_vertices(std::vector<std::array<int, 4>>& tets) {
  std::vector<int> pinched;
  for (const auto& [v, fans] : boundary_fans(boundary_faces(tets))) {
    if (fans > 1) pinched.push_back(v);
  }
  if (pinched.empty()) return false;
  std::map<int, std::vector<int>> incident;
  for (size_t t = 0; t < tets.size(); ++t) {
    for (const int v : tets[t]) incident[v].push_back(static_cast<int>(t));
  }
  std::vector<bool> remove(tets.size(), false);
  for (const int v : pinched) {
    const std::vector<int>& around = incident[v];
    // Union-find over the tets around v, joined by shared faces through v.
    std::vector<int> parent(around.size());
    for (size_t i = 0; i < around.size(); ++i) parent[i] = static_cast<int>(i);
    const auto find = [&parent](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    std::map<std::array<int, 3>, int> face_owner;
    for (size_t i = 0; i < around.size(); ++i) {
      const auto& t = tets[around[i]];
      for (int f = 0; f < 4; ++f) {
        const std::array<int, 3> key = sorted_face(t, f);
        if (std::find(key.begin(), key.end(), v) == key.end()) continue;
        const auto [it, inserted] = face_owner.emplace(key, static_cast<int>(i));
        if (!inserted) parent[find(static_cast<int>(i))] = find(it->second);
      }
    }
    std::map<int, int> group_size;
    for (size_t i = 0; i < around.size(); ++i) ++group_size[find(static_cast<int>(i))];
    int largest = -1;
    if (group_size.size() > 1) {
      largest = group_size.begin()->first;
      for (const auto& [root, size] : group_size) {
        if (size > group_size[largest]) largest = root;
      }
    }
    for (size_t i = 0; i < around.size(); ++i) {
      if (find(static_cast<int>(i)) != largest) remove[around[i]] = true;
    }
  }
  std::vector<std::array<int, 4>> kept;
  for (size_t t = 0; t < tets.size(); ++t) {
    if (!remove[t]) kept.push_back(tets[t]);
  }
  tets.swap(kept);
  return true;
}

bool tet_acceptable(const MeshedSolid& m, const std::array<int, 4>& t, double min_volume,
                    double min_dihedral) {
  const Vec3& a = m.nodes[t[0]];
  const Vec3& b = m.nodes[t[1]];
  const Vec3& c = m.nodes[t[2]];
  const Vec3& d = m.nodes[t[3]];
  return tet_signed_volume(a, b, c, d) >= min_volume &&
         tet_min_dihedral_deg(a, b, c, d) >= min_dihedral;
}

}  // namespace

std::vector<std::array<int, 3>> boundary_faces(const std::vector<std::array<int, 4>>& tets) {
  std::map<std::array<int, 3>, int> count;
  for (const auto& t : tets) {
    for (int f = 0; f < 4; ++f) ++count[sorted_face(t, f)];
  }
  std::vector<std::array<int, 3>> faces;
  for (const auto& t : tets) {
    for (int f = 0; f < 4; ++f) {
      if (count[sorted_face(t, f)] == 1) {
        faces.push_back({t[kTetFaces[f][0]], t[kTetFaces[f][1]], t[kTetFaces[f][2]]});
      }
    }
  }
  return faces;
}

namespace {

// The grid's tets (grid node indices) as a mesh of their own nodes, with the
// boundary nodes pulled onto the surface. The mesh's tets are in the order
// of `tets`.
MeshedSolid snap_grid_tets(const ImplicitSolid& shape, const Grid& grid,
                           std::vector<std::array<int, 4>> tets, const TetMesherSettings& settings,
                           TetMesherReport& report) {
  // Compact the used grid nodes, in grid order (deterministic numbering).
  std::map<int, int> renumber;
  for (const auto& t : tets) {
    for (const int v : t) renumber[v] = 0;
  }
  MeshedSolid mesh;
  for (auto& [grid_id, new_id] : renumber) {
    new_id = static_cast<int>(mesh.nodes.size());
    const int k = grid_id % (grid.nz + 1);
    const int j = (grid_id / (grid.nz + 1)) % (grid.ny + 1);
    const int i = grid_id / ((grid.nz + 1) * (grid.ny + 1));
    mesh.nodes.push_back(grid.position(i, j, k));
  }
  for (auto& t : tets) {
    for (auto& v : t) v = renumber[v];
  }
  mesh.tets = tets;

  std::vector<std::vector<int>> node_tets(mesh.nodes.size());
  for (size_t ti = 0; ti < tets.size(); ++ti) {
    for (const int v : tets[ti]) node_tets[v].push_back(static_cast<int>(ti));
  }
  const auto faces = boundary_faces(tets);
  std::vector<int> boundary_nodes;
  for (const auto& f : faces) boundary_nodes.insert(boundary_nodes.end(), f.begin(), f.end());
  std::sort(boundary_nodes.begin(), boundary_nodes.end());
  boundary_nodes.erase(std::unique(boundary_nodes.begin(), boundary_nodes.end()),
                       boundary_nodes.end());
  report.boundary_nodes = static_cast<int>(boundary_nodes.size());

  // Snap: try the full move, then half, then a quarter; refuse a fraction
  // that makes any incident tet smaller or flatter than the floor (or worse
  // than it already was, for tets already under the floor).
  const double grid_tet_volume = std::pow(settings.cell_mm, 3) / 6.0;
  const double min_volume = settings.min_volume_fraction * grid_tet_volume;
  std::vector<double> moved_fraction(mesh.nodes.size(), 0.0);
  // Moves node v towards `target`, the first of `fractions` of the way
  // that keeps its tets above the floor, or not at all. Its start is a
  // copy: the tries overwrite the node, and a refused move puts it back.
  const auto move_guarded = [&](int v, const Vec3& target,
                                std::initializer_list<double> fractions) {
    const Vec3 start = mesh.nodes[v];
    for (const double fraction : fractions) {
      mesh.nodes[v] = start + fraction * (target - start);
      bool ok = true;
      for (const int ti : node_tets[v]) {
        ok = ok && tet_acceptable(mesh, mesh.tets[ti], min_volume, settings.min_dihedral_deg);
      }
      if (ok) return fraction;
    }
    mesh.nodes[v] = start;
    return 0.0;
  };
  // Interior nodes and their edge neighbours, for the smoothing between
  // snapping rounds: an interior node moved towards the mean of its
  // neighbours often unblocks a boundary node whose snap flattened a tet.
  std::vector<bool> on_boundary(mesh.nodes.size(), false);
  for (const int v : boundary_nodes) on_boundary[v] = true;
  std::vector<std::vector<int>> neighbours(mesh.nodes.size());
  for (const auto& t : mesh.tets) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        if (a != b) neighbours[t[a]].push_back(t[b]);
      }
    }
  }
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  for (int round = 0; round <= settings.smoothing_rounds; ++round) {
    if (round > 0) {
      for (size_t v = 0; v < mesh.nodes.size(); ++v) {
        if (on_boundary[v] || neighbours[v].empty()) continue;
        Vec3 mean = Vec3::Zero();
        for (const int u : neighbours[v]) mean += mesh.nodes[u];
        mean /= static_cast<double>(neighbours[v].size());
        move_guarded(static_cast<int>(v), mean, {0.5, 0.25});
      }
    }
    for (int pass = 0; pass < settings.snap_passes; ++pass) {
      for (const int v : boundary_nodes) {
        moved_fraction[v] =
            move_guarded(v, shape.project_to_surface(mesh.nodes[v]), {1.0, 0.5, 0.25});
      }
    }
  }
  for (const int v : boundary_nodes) {
    const double gap = std::abs(shape.value(mesh.nodes[v]));
    report.max_surface_gap_mm = std::max(report.max_surface_gap_mm, gap);
    if (moved_fraction[v] >= 1.0) {
      ++report.snapped_fully;
    } else if (moved_fraction[v] > 0.0) {
      ++report.snapped_partly;
    } else {
      ++report.not_snapped;
    }
  }
  mesh.boundary = faces;

  TriangleMesh surface{mesh.nodes, mesh.boundary};
  report.nonmanifold_boundary_edges = check_closed(surface).bad_edges;
  return mesh;
}

void make_boundary_manifold(std::vector<std::array<int, 4>>& tets) {
  constexpr int kMaxTopologyPasses = 10;
  for (int pass = 0; pass < kMaxTopologyPasses; ++pass) {
    remove_nonmanifold_edges(tets);
    if (!remove_pinched_vertices(tets)) break;
  }
}

// Nodes whose lumped mass is under `fraction` of the median node's.
std::vector<bool> light_nodes(const MeshedSolid& mesh, double fraction) {
  const std::vector<double> mass = node_mass_over_median(mesh);
  std::vector<bool> light(mass.size(), false);
  for (size_t v = 0; v < mass.size(); ++v) light[v] = mass[v] < fraction;
  return light;
}

}  // namespace

MeshedSolid mesh_implicit_solid(const ImplicitSolid& shape, const TetMesherSettings& settings,
                                TetMesherReport& report) {
  const Grid grid = make_grid(shape, settings);
  auto tets = inside_tets(shape, grid);
  make_boundary_manifold(tets);
  // A boundary node the centroid rule left with a tet or two snaps into a
  // node far lighter than its neighbours, and under a tool such a node is
  // pushed on its own: its few small tets stretch many times their length.
  // Its tets are peeled off the grid and the rest snapped again, until no
  // node is light (or the rounds run out; the report says how many remain).
  int peeled = 0;
  for (int round = 0;; ++round) {
    report = TetMesherReport{};
    report.grid_cells = grid.nx * grid.ny * grid.nz;
    report.peeled_tets = peeled;
    MeshedSolid mesh = snap_grid_tets(shape, grid, tets, settings, report);
    const std::vector<bool> light = light_nodes(mesh, settings.min_node_mass_fraction);
    report.light_nodes = static_cast<int>(std::count(light.begin(), light.end(), true));
    if (report.light_nodes == 0 || round == settings.peel_rounds) return mesh;
    std::vector<std::array<int, 4>> kept;
    for (size_t t = 0; t < tets.size(); ++t) {
      const auto& local = mesh.tets[t];
      const bool on_light =
          light[local[0]] || light[local[1]] || light[local[2]] || light[local[3]];
      if (!on_light) kept.push_back(tets[t]);
    }
    peeled += static_cast<int>(tets.size() - kept.size());
    tets.swap(kept);
    make_boundary_manifold(tets);
  }
}

}  // namespace fahr::scenegen
