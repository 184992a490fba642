// Parametric closed surfaces: quads of a parameter grid split into two
// triangles each; shared grid points are shared vertices, so the surfaces are
// watertight by construction.
#include "fahr/scenegen/param_surfaces.h"

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "fahr/scenegen/mesh_checks.h"
#include "fahr/scenegen/tet_mesher.h"

namespace fahr::scenegen {
namespace {

void add_quad(TriangleMesh& mesh, int a, int b, int c, int d) {
  // Quad a-b-c-d counter-clockwise; split along a-c.
  mesh.triangles.push_back({a, b, c});
  mesh.triangles.push_back({a, c, d});
}

double grid_coordinate(int i, int n) {
  return static_cast<double>(i) / static_cast<double>(n);
}

}  // namespace

void orient_outward(TriangleMesh& mesh) {
  if (enclosed_volume(mesh) < 0.0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  }
}

TriangleMesh make_param_box(const BoxMap& map, int nu, int nv, int nw) {
  TriangleMesh mesh;
  const int n[3] = {nu, nv, nw};
  const auto lattice = [&](int i, int j, int k) { return (i * (nv + 1) + j) * (nw + 1) + k; };
  std::vector<int> index(static_cast<size_t>((nu + 1) * (nv + 1) * (nw + 1)), -1);
  for (int i = 0; i <= nu; ++i) {
    for (int j = 0; j <= nv; ++j) {
      for (int k = 0; k <= nw; ++k) {
        const bool on_boundary = i == 0 || i == nu || j == 0 || j == nv || k == 0 || k == nw;
        if (!on_boundary) continue;
        index[static_cast<size_t>(lattice(i, j, k))] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(
            map(grid_coordinate(i, nu), grid_coordinate(j, nv), grid_coordinate(k, nw)));
      }
    }
  }
  // Each face of the cube: fixed axis f at value 0 or n[f]; the free axes a, b
  // follow f cyclically, so e_a x e_b = e_f (outward on the far face).
  for (int f = 0; f < 3; ++f) {
    const int a = (f + 1) % 3;
    const int b = (f + 2) % 3;
    for (const int side : {0, 1}) {
      for (int p = 0; p < n[a]; ++p) {
        for (int q = 0; q < n[b]; ++q) {
          int c[4][3];
          const int pa[4] = {p, p + 1, p + 1, p};
          const int qb[4] = {q, q, q + 1, q + 1};
          for (int r = 0; r < 4; ++r) {
            c[r][f] = side * n[f];
            c[r][a] = pa[r];
            c[r][b] = qb[r];
          }
          int id[4];
          for (int r = 0; r < 4; ++r) {
            id[r] = index[static_cast<size_t>(lattice(c[r][0], c[r][1], c[r][2]))];
          }
          if (side == 1) {
            add_quad(mesh, id[0], id[1], id[2], id[3]);
          } else {
            add_quad(mesh, id[0], id[3], id[2], id[1]);
          }
        }
      }
    }
  }
  orient_outward(mesh);
  return mesh;
}

TriangleMesh make_param_box(const ParamBox& box) {
  return make_param_box(box.map, box.nu, box.nv, box.nw);
}

namespace {

// The box's lattice points, (i, j, k) at (i * (nv + 1) + j) * (nw + 1) + k.
std::vector<Vec3> lattice_points(const ParamBox& box) {
  std::vector<Vec3> points;
  points.reserve(static_cast<size_t>(box.nu + 1) * static_cast<size_t>(box.nv + 1) *
                 static_cast<size_t>(box.nw + 1));
  for (int i = 0; i <= box.nu; ++i) {
    for (int j = 0; j <= box.nv; ++j) {
      for (int k = 0; k <= box.nw; ++k) {
        points.push_back(box.map(grid_coordinate(i, box.nu), grid_coordinate(j, box.nv),
                                 grid_coordinate(k, box.nw)));
      }
    }
  }
  return points;
}

// Every cell split into six Kuhn tets: a monotone path from corner (0,0,0)
// to (1,1,1) per axis permutation, every cell with the same main diagonal,
// so shared faces split alike (conforming). `visit(tet, sign)` gets lattice
// indices and sign(permutation): the tet's orientation under the identity map.
template <class Visit>
void each_kuhn_tet(const ParamBox& box, Visit&& visit) {
  constexpr int kPermutations[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                       {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  constexpr int kPermutationSign[6] = {1, 1, 1, -1, -1, -1};
  const auto index = [&box](const int(&c)[3]) {
    return (c[0] * (box.nv + 1) + c[1]) * (box.nw + 1) + c[2];
  };
  for (int i = 0; i < box.nu; ++i) {
    for (int j = 0; j < box.nv; ++j) {
      for (int k = 0; k < box.nw; ++k) {
        for (int p = 0; p < 6; ++p) {
          int corner[3] = {i, j, k};
          std::array<int, 4> tet{};
          tet[0] = index(corner);
          for (int step = 0; step < 3; ++step) {
            ++corner[kPermutations[p][step]];
            tet[static_cast<size_t>(step) + 1] = index(corner);
          }
          visit(tet, kPermutationSign[p]);
        }
      }
    }
  }
}

double signed_volume(const std::vector<Vec3>& p, const std::array<int, 4>& t) {
  const Vec3& a = p[static_cast<size_t>(t[0])];
  return (p[static_cast<size_t>(t[1])] - a)
      .dot((p[static_cast<size_t>(t[2])] - a).cross(p[static_cast<size_t>(t[3])] - a));
}

}  // namespace

int folded_box_tets(const ParamBox& box) {
  const std::vector<Vec3> points = lattice_points(box);
  int positive = 0;
  int negative = 0;
  int flat = 0;
  each_kuhn_tet(box, [&](const std::array<int, 4>& tet, int sign) {
    const double volume = sign * signed_volume(points, tet);
    if (volume > 0.0) {
      ++positive;
    } else if (volume < 0.0) {
      ++negative;
    } else {
      ++flat;
    }
  });
  return std::min(positive, negative) + flat;
}

MeshedSolid param_box_tets(const ParamBox& box) {
  MeshedSolid mesh;
  mesh.nodes = lattice_points(box);
  // Each tet turned to positive volume, as TetGen files and the FEM expect
  // (the generator writes no mesh of a box that folds: folded_box_tets > 0).
  each_kuhn_tet(box, [&](std::array<int, 4> tet, int) {
    if (signed_volume(mesh.nodes, tet) < 0.0) std::swap(tet[2], tet[3]);
    mesh.tets.push_back(tet);
  });
  mesh.boundary = boundary_faces(mesh.tets);
  return mesh;
}

TriangleMesh make_param_torus(const TorusMap& map, int n_around, int n_loop) {
  TriangleMesh mesh;
  for (int i = 0; i < n_around; ++i) {
    for (int j = 0; j < n_loop; ++j) {
      mesh.vertices.push_back(map(grid_coordinate(i, n_around), grid_coordinate(j, n_loop)));
    }
  }
  const auto id = [&](int i, int j) { return (i % n_around) * n_loop + (j % n_loop); };
  for (int i = 0; i < n_around; ++i) {
    for (int j = 0; j < n_loop; ++j) {
      add_quad(mesh, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    }
  }
  orient_outward(mesh);
  return mesh;
}

TriangleMesh make_param_sphere(const SphereMap& map, int n_along, int n_around) {
  TriangleMesh mesh;
  mesh.vertices.push_back(map(0.0, 0.0));
  for (int i = 1; i < n_along; ++i) {
    for (int j = 0; j < n_around; ++j) {
      mesh.vertices.push_back(map(grid_coordinate(i, n_along), grid_coordinate(j, n_around)));
    }
  }
  const int last_pole = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(map(1.0, 0.0));
  const auto id = [&](int i, int j) { return 1 + (i - 1) * n_around + (j % n_around); };
  for (int j = 0; j < n_around; ++j) {
    mesh.triangles.push_back({0, id(1, j + 1), id(1, j)});
    mesh.triangles.push_back({last_pole, id(n_along - 1, j), id(n_along - 1, j + 1)});
  }
  for (int i = 1; i + 1 < n_along; ++i) {
    for (int j = 0; j < n_around; ++j) {
      add_quad(mesh, id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
    }
  }
  orient_outward(mesh);
  return mesh;
}

}  // namespace fahr::scenegen
