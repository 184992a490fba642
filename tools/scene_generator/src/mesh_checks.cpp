// Checks used to refuse a bad scene before it is written, and by the test.
#include "fahr/scenegen/mesh_checks.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace fahr::scenegen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Interior dihedral angle along edge (p, q) between the faces towards r and s:
// the angle between r and s projected onto the plane normal to the edge.
double dihedral_at_edge(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
  const Vec3 e = (q - p).normalized();
  Vec3 u = r - p;
  Vec3 v = s - p;
  u -= u.dot(e) * e;
  v -= v.dot(e) * e;
  const double nu = u.norm();
  const double nv = v.norm();
  if (nu <= 0.0 || nv <= 0.0) {
    return 0.0;  // flat tet: report the worst angle rather than NaN
  }
  const double c = std::clamp(u.dot(v) / (nu * nv), -1.0, 1.0);
  return std::acos(c) * 180.0 / kPi;
}

// Closest point on triangle (a, b, c) to p, by Voronoi regions of the
// vertices, edges and face (the textbook case analysis).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denom = va + vb + vc;
  if (denom <= 0.0) return a;  // degenerate triangle: any vertex is as good
  return a + ab * (vb / denom) + ac * (vc / denom);
}

}  // namespace

double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double tet_min_dihedral_deg(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const std::array<const Vec3*, 4> v{&a, &b, &c, &d};
  constexpr int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  double smallest = 180.0;
  for (const auto& e : kEdges) {
    smallest = std::min(smallest, dihedral_at_edge(*v[e[0]], *v[e[1]], *v[e[2]], *v[e[3]]));
  }
  return smallest;
}

double tet_radius_ratio(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ad = d - a;
  const double six_volume = std::abs(ab.dot(ac.cross(ad)));
  const double area_sum = 0.5 * (ab.cross(ac).norm() + ab.cross(ad).norm() + ac.cross(ad).norm() +
                                 (c - b).cross(d - b).norm());
  if (six_volume <= 0.0 || area_sum <= 0.0) return 0.0;
  const double inradius = 0.5 * six_volume / area_sum;  // 3 V / S
  // Circumcentre o - a solves 2 [ab ac ad]^T x = [|ab|^2 |ac|^2 |ad|^2].
  Eigen::Matrix3d edges;
  edges.row(0) = ab;
  edges.row(1) = ac;
  edges.row(2) = ad;
  const Vec3 rhs(0.5 * ab.squaredNorm(), 0.5 * ac.squaredNorm(), 0.5 * ad.squaredNorm());
  const double circumradius = edges.partialPivLu().solve(rhs).norm();
  return std::clamp(3.0 * inradius / circumradius, 0.0, 1.0);
}

double enclosed_volume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles) {
    six_volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return six_volume / 6.0;
}

ClosednessReport check_closed(const TriangleMesh& mesh) {
  // Directed edge counts keyed by (from, to); a closed, consistently oriented
  // surface runs every edge once in each direction.
  std::map<std::pair<int, int>, int> directed;
  // Triangles of each undirected edge, for the fold test.
  std::map<std::pair<int, int>, std::vector<int>> edge_triangles;
  std::vector<Vec3> normals;
  normals.reserve(mesh.triangles.size());
  ClosednessReport report;
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    const bool degenerate = n.norm() <= 1e-12 || t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    if (degenerate) ++report.degenerate_triangles;
    normals.push_back(degenerate ? Vec3::Zero() : Vec3(n.normalized()));
    const int index = static_cast<int>(normals.size()) - 1;
    for (int k = 0; k < 3; ++k) {
      ++directed[{t[k], t[(k + 1) % 3]}];
      const auto key = std::minmax(t[k], t[(k + 1) % 3]);
      edge_triangles[{key.first, key.second}].push_back(index);
    }
  }
  for (const auto& [edge, triangles] : edge_triangles) {
    if (triangles.size() != 2) continue;
    const Vec3& n1 = normals[static_cast<size_t>(triangles[0])];
    const Vec3& n2 = normals[static_cast<size_t>(triangles[1])];
    if (n1.isZero() || n2.isZero()) continue;
    if ((n1 + n2).norm() < kFoldedNormalSum) ++report.folded_edges;
    const double opening = 180.0 - std::acos(std::clamp(n1.dot(n2), -1.0, 1.0)) * 180.0 / kPi;
    report.sharpest_edge_deg = std::min(report.sharpest_edge_deg, opening);
  }
  std::map<std::pair<int, int>, std::pair<int, int>> undirected;
  for (const auto& [edge, count] : directed) {
    const auto key = std::minmax(edge.first, edge.second);
    auto& slot = undirected[{key.first, key.second}];
    if (edge.first < edge.second) {
      slot.first += count;
    } else {
      slot.second += count;
    }
  }
  report.edge_count = static_cast<int>(undirected.size());
  for (const auto& [edge, counts] : undirected) {
    if (counts.first + counts.second != 2) {
      ++report.bad_edges;
    } else if (counts.first != 1) {
      ++report.inconsistent_edges;
    }
  }
  // A vertex is pinched when its triangles, joined through the edges they
  // share at it, form more than one fan (two sheets touching at a point).
  std::map<int, std::vector<std::pair<int, int>>> spokes;  // vertex -> (edge end, triangle)
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      spokes[tri[k]].push_back({tri[(k + 1) % 3], static_cast<int>(t)});
      spokes[tri[k]].push_back({tri[(k + 2) % 3], static_cast<int>(t)});
    }
  }
  for (auto& [vertex, around] : spokes) {
    std::map<int, int> parent;  // triangle -> parent triangle
    const auto find = [&parent](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    for (const auto& [end, tri] : around) parent[tri] = tri;
    std::map<int, int> first_at_end;  // edge end -> a triangle using the edge (vertex, end)
    for (const auto& [end, tri] : around) {
      const auto [it, inserted] = first_at_end.emplace(end, tri);
      if (!inserted) parent[find(tri)] = find(it->second);
    }
    int fans = 0;
    for (const auto& [tri, up] : parent) {
      if (find(tri) == tri) ++fans;
    }
    if (fans > 1) ++report.pinched_vertices;
  }
  return report;
}

double winding_number(const TriangleMesh& mesh, const Vec3& p) {
  // Van Oosterom and Strackee's solid angle of each triangle seen from p.
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] - p;
    const Vec3 b = mesh.vertices[t[1]] - p;
    const Vec3 c = mesh.vertices[t[2]] - p;
    const double la = a.norm();
    const double lb = b.norm();
    const double lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    total += 2.0 * std::atan2(numerator, denominator);
  }
  return total / (4.0 * kPi);
}

double distance_to_surface(const TriangleMesh& mesh, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    const Vec3 q =
        closest_point_on_triangle(p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
    best = std::min(best, (q - p).squaredNorm());
  }
  return std::sqrt(best);
}

TetQuality tet_quality(const MeshedSolid& mesh) {
  TetQuality q;
  q.tet_count = static_cast<int>(mesh.tets.size());
  q.min_volume_mm3 = std::numeric_limits<double>::infinity();
  q.max_volume_mm3 = -std::numeric_limits<double>::infinity();
  q.min_dihedral_deg = 180.0;
  q.max_dihedral_deg = 0.0;
  q.min_radius_ratio = 1.0;
  constexpr double kSliverDeg = 10.0;  // common threshold for "poor" FEM tets
  for (const auto& t : mesh.tets) {
    const Vec3& a = mesh.nodes[t[0]];
    const Vec3& b = mesh.nodes[t[1]];
    const Vec3& c = mesh.nodes[t[2]];
    const Vec3& d = mesh.nodes[t[3]];
    const double v = tet_signed_volume(a, b, c, d);
    q.min_volume_mm3 = std::min(q.min_volume_mm3, v);
    q.max_volume_mm3 = std::max(q.max_volume_mm3, v);
    const double dmin = tet_min_dihedral_deg(a, b, c, d);
    q.min_dihedral_deg = std::min(q.min_dihedral_deg, dmin);
    if (dmin < kSliverDeg) ++q.below_10_deg;
    const double ratio = tet_radius_ratio(a, b, c, d);
    q.min_radius_ratio = std::min(q.min_radius_ratio, ratio);
    q.radius_ratio_below_0_1 += ratio < 0.1 ? 1 : 0;
    q.radius_ratio_below_0_3 += ratio < 0.3 ? 1 : 0;
    // The largest dihedral: evaluate all six via the same helper on permutations.
    constexpr int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                  {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    const std::array<const Vec3*, 4> v4{&a, &b, &c, &d};
    for (const auto& e : kEdges) {
      q.max_dihedral_deg = std::max(q.max_dihedral_deg,
                                    dihedral_at_edge(*v4[e[0]], *v4[e[1]], *v4[e[2]], *v4[e[3]]));
    }
  }
  return q;
}

std::array<Vec3, 2> bounds(const std::vector<Vec3>& points) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {lo, hi};
}

std::vector<double> node_mass_over_median(const MeshedSolid& mesh) {
  std::vector<double> mass(mesh.nodes.size(), 0.0);
  for (const auto& t : mesh.tets) {
    const double quarter = 0.25 * tet_signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]],
                                                    mesh.nodes[t[2]], mesh.nodes[t[3]]);
    for (const int v : t) mass[v] += quarter;
  }
  if (mass.empty()) return mass;
  std::vector<double> sorted = mass;
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  const double median = *middle;
  for (double& m : mass) m /= median;
  return mass;
}

}  // namespace fahr::scenegen
