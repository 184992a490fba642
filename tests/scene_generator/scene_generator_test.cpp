// Runs fahr_scene_generator twice with its defaults and checks that both runs
// and the committed meshes/neonatal files are byte-identical (so what is
// committed is exactly the generator's output), that every tet has positive
// volume, that every surface is closed and outward oriented, and that
// fahr::geometry reads every surface as closed, manifold, fold-free and
// non-degenerate and builds a signed distance field for it.
#include <gtest/gtest.h>
#include <stdlib.h>  // mkdtemp (POSIX)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_quality.h"
#include "fahr/scenegen/mesh_checks.h"
#include "fahr/scenegen/mesh_readers.h"
#include "fahr/scenegen/scene_parameters.h"
#include "fahr/scenegen/tet_mesher.h"

namespace {

namespace fs = std::filesystem;
using fahr::scenegen::MeshedSolid;
using fahr::scenegen::TriangleMesh;
using fahr::scenegen::Vec3;

#ifndef FAHR_SCENE_GENERATOR
#error "FAHR_SCENE_GENERATOR must name the generator executable"
#endif

const std::vector<std::string> kSceneFiles = {"tongue.node",
                                              "tongue.ele",
                                              "tongue.face",
                                              "tongue_fixed_nodes.txt",
                                              "palate.obj",
                                              "jaw.obj",
                                              "hyoid.obj",
                                              "lips_face.obj",
                                              "miller0.obj",
                                              "larynx_trachea.obj",
                                              "miller1.obj",
                                              "scene_parameters.txt",
                                              "soft_palate.obj",
                                              "epiglottis.obj",
                                              "pharynx.obj",
                                              "epiglottis.node",
                                              "epiglottis.ele",
                                              "epiglottis.face",
                                              "epiglottis_fixed_nodes.txt"};
const std::vector<std::string> kSurfaces = {
    "palate",     "jaw",         "hyoid",   "lips_face", "larynx_trachea",
    "epiglottis", "soft_palate", "pharynx", "miller0",   "miller1"};
constexpr double kMetresPerMm = 1e-3;
constexpr double kSdfCellM = 1e-3;  // the 1 mm cell the haptic and AIST code use

std::string slurp(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// A fresh, unique directory per run (mkdtemp), so parallel runs do not collide.
fs::path run_generator(const std::string& tag) {
  std::string pattern = (fs::temp_directory_path() / ("fahr_scenegen_" + tag + "_XXXXXX")).string();
  if (mkdtemp(pattern.data()) == nullptr) {
    ADD_FAILURE() << "cannot create a temporary directory from " << pattern;
    return {};
  }
  fs::path dir = pattern;  // not const: returned by move
  const std::string command = std::string("\"") + FAHR_SCENE_GENERATOR + "\" --out \"" +
                              dir.string() + "\" > \"" + (dir / "generator.log").string() + "\"";
  EXPECT_EQ(std::system(command.c_str()), 0) << "generator failed; see " << dir / "generator.log";
  return dir;
}

// Every tet's nodes exist and its volume is positive; the boundary is closed
// and outward.
void expect_valid_tets(const MeshedSolid& mesh) {
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    for (const int v : t) ASSERT_LT(static_cast<size_t>(v), mesh.nodes.size()) << "tet " << i;
    EXPECT_GT(fahr::scenegen::tet_signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]],
                                                mesh.nodes[t[2]], mesh.nodes[t[3]]),
              0.0)
        << "tet " << i;
  }
  const TriangleMesh boundary{mesh.nodes, mesh.boundary};
  const auto closed = fahr::scenegen::check_closed(boundary);
  EXPECT_TRUE(closed.closed_and_oriented())
      << closed.bad_edges << " bad, " << closed.inconsistent_edges << " inconsistent edges";
  EXPECT_GT(fahr::scenegen::enclosed_volume(boundary), 0.0) << "boundary not outward";
}

class SceneGeneratorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    first_ = new fs::path(run_generator("a"));
    second_ = new fs::path(run_generator("b"));
  }
  static void TearDownTestSuite() {
    for (fs::path* dir : {first_, second_}) {
      fs::remove_all(*dir);
      delete dir;
    }
  }
  static fs::path* first_;
  static fs::path* second_;
};
fs::path* SceneGeneratorTest::first_ = nullptr;
fs::path* SceneGeneratorTest::second_ = nullptr;

TEST_F(SceneGeneratorTest, TwoRunsGiveIdenticalBytes) {
  for (const auto& name : kSceneFiles) {
    const std::string a = slurp(*first_ / name);
    ASSERT_FALSE(a.empty()) << name << " missing or empty";
    EXPECT_TRUE(a == slurp(*second_ / name)) << name << " differs between two runs";
  }
}

TEST_F(SceneGeneratorTest, CommittedFilesAreTheGeneratorOutput) {
  const fs::path committed = FAHR_COMMITTED_SCENE_DIR;
  for (const auto& name : kSceneFiles) {
    EXPECT_TRUE(slurp(*first_ / name) == slurp(committed / name))
        << committed / name << " is not what the generator writes; rerun "
        << "fahr_scene_generator --out meshes/neonatal from the repository root";
  }
}

// The numbers after `key` in `text` (up to the line's end): "[a, b, c]" or
// one value.
std::vector<double> numbers_after(const std::string& text, const std::string& key) {
  std::vector<double> out;
  const auto at = text.find(key);
  if (at == std::string::npos) return out;
  const auto end = text.find('\n', at);
  std::string line = text.substr(at + key.size(), end - at - key.size());
  for (char& c : line) {
    if (c == '[' || c == ']' || c == ',' || c == ':') c = ' ';
  }
  std::istringstream in(line);
  // Up to the next key (a word): the generator prints them on one line.
  for (double v = 0.0; in >> v;) out.push_back(v);
  return out;
}

// The shipped scene's glottic_view opening is the generator's glottic slit
// for the shipped parameters: a larynx moved in the generator without the
// scene following would score a view of nothing.
TEST_F(SceneGeneratorTest, TheScenesGlotticOpeningIsTheGeneratedSlit) {
  const std::string log = slurp(*first_ / "generator.log");
  const std::string scene = slurp(FAHR_NEONATAL_SCENE);
  ASSERT_NE(log.find("glottic_view "), std::string::npos) << "the generator printed no opening";
  for (const std::string key : {"opening_centre_m", "opening_normal", "opening_major_axis",
                                "opening_radius_m", "opening_minor_radius_m"}) {
    const auto generated = numbers_after(log, key + " ");
    const auto shipped = numbers_after(scene, "  " + key + ":");
    ASSERT_FALSE(generated.empty()) << key;
    ASSERT_EQ(generated.size(), shipped.size()) << key;
    for (std::size_t i = 0; i < generated.size(); ++i) {
      EXPECT_NEAR(generated[i], shipped[i], 1e-6) << key << "[" << i << "]";
    }
  }
}

TEST_F(SceneGeneratorTest, TetsHavePositiveVolumeAndBoundaryIsClosed) {
  MeshedSolid tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  // The tongue (about 5,500 tets) with the floor of the mouth (about 2,600).
  EXPECT_GE(tongue.tets.size(), 5600u);
  EXPECT_LE(tongue.tets.size(), 10000u);
  expect_valid_tets(tongue);
}

// Snapping and smoothing shorten or refuse every move that would leave a
// tet flatter or smaller than the floor (the generator's
// --tongue-snap-min-dihedral-deg and --tongue-snap-min-volume-fraction of
// a grid tet); the grid's Kuhn tets start well above it. So no tet of the
// tongue ends under it (less the written coordinates' rounding). A refused
// smoothing move that was not undone left the shipped tongue a tet 2 %
// under the volume floor.
TEST_F(SceneGeneratorTest, NoTongueTetIsUnderTheSnappingFloor) {
  MeshedSolid tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  const fahr::scenegen::TongueParameters defaults;
  const double floor_volume =
      defaults.snap_min_volume_fraction * std::pow(defaults.cell_mm, 3) / 6.0;
  int under = 0;
  double smallest = floor_volume;
  for (const auto& t : tongue.tets) {
    const Vec3& a = tongue.nodes[t[0]];
    const Vec3& b = tongue.nodes[t[1]];
    const Vec3& c = tongue.nodes[t[2]];
    const Vec3& d = tongue.nodes[t[3]];
    const double volume = fahr::scenegen::tet_signed_volume(a, b, c, d);
    smallest = std::min(smallest, volume);
    const bool flat =
        fahr::scenegen::tet_min_dihedral_deg(a, b, c, d) < defaults.snap_min_dihedral_deg - 0.01;
    under += volume < 0.999 * floor_volume || flat ? 1 : 0;
  }
  EXPECT_EQ(under, 0) << "smallest volume " << smallest << " mm^3 against the floor "
                      << floor_volume;
}

// The generator's radius ratio (which its quality line prints) is the
// geometry library's, tet by tet, on the generated tongue; the regular tet
// scores 1 and a flat one 0.
TEST_F(SceneGeneratorTest, RadiusRatioIsTheGeometryLibrarys) {
  using fahr::scenegen::tet_radius_ratio;
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0.5, std::sqrt(3.0) / 2.0, 0);
  const Vec3 apex(0.5, std::sqrt(3.0) / 6.0, std::sqrt(2.0 / 3.0));
  EXPECT_NEAR(tet_radius_ratio(a, b, c, apex), 1.0, 1e-12);
  EXPECT_EQ(tet_radius_ratio(a, b, c, Vec3(0.3, 0.2, 0.0)), 0.0);
  MeshedSolid tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  double smallest = 1.0;
  for (const auto& t : tongue.tets) {
    const auto& n = tongue.nodes;
    const double ours = tet_radius_ratio(n[t[0]], n[t[1]], n[t[2]], n[t[3]]);
    const double theirs =
        fahr::geometry::tet_shape(n[t[0]], n[t[1]], n[t[2]], n[t[3]]).radius_ratio;
    ASSERT_NEAR(ours, theirs, 1e-9);
    smallest = std::min(smallest, ours);
  }
  EXPECT_NEAR(fahr::scenegen::tet_quality(tongue).min_radius_ratio, smallest, 0.0);
}

TEST_F(SceneGeneratorTest, SurfacesAreClosedAndOutward) {
  for (const auto& name : kSurfaces) {
    TriangleMesh mesh;
    std::string error;
    ASSERT_TRUE(fahr::scenegen::read_obj((*first_ / (name + ".obj")).string(), mesh, error))
        << error;
    const auto closed = fahr::scenegen::check_closed(mesh);
    EXPECT_EQ(closed.bad_edges, 0) << name << ": edges not shared by exactly two triangles";
    EXPECT_EQ(closed.inconsistent_edges, 0) << name << ": inconsistent orientation";
    EXPECT_GT(fahr::scenegen::enclosed_volume(mesh), 0.0) << name << ": not outward";
  }
}

// What the geometry library needs of a rigid obstacle or tool: every
// topology count zero, and a signed (not unsigned) field.
void expect_clean_and_signed(const fahr::geometry::SurfaceMesh& surface, const std::string& name) {
  const fahr::geometry::SurfaceTopology& t = surface.topology();
  EXPECT_EQ(t.boundary_edge_count, 0u) << name << ": boundary edges";
  EXPECT_EQ(t.non_manifold_edge_count, 0u) << name << ": non-manifold edges";
  EXPECT_EQ(t.inconsistent_edge_count, 0u) << name << ": inconsistently oriented edges";
  EXPECT_EQ(t.non_manifold_vertex_count, 0u) << name << ": non-manifold vertices";
  EXPECT_EQ(t.folded_edge_count, 0u) << name << ": folded (back to back) edges";
  EXPECT_EQ(t.degenerate_triangle_count, 0u) << name << ": degenerate triangles";
  EXPECT_GT(surface.enclosed_volume_m3(), 0.0) << name << ": not outward";
  fahr::geometry::SdfOptions options;
  options.cell_size_m = kSdfCellM;
  options.unsigned_mode = false;
  try {
    const fahr::geometry::SignedDistanceField field(surface, options);
    EXPECT_TRUE(field.is_signed()) << name;
    // A point well outside the box must come out positive.
    const Eigen::Vector3d outside =
        surface.bounds_max() + Eigen::Vector3d::Constant(5.0 * kSdfCellM);
    EXPECT_GT(field.query(outside).distance_m, 0.0) << name << ": sign outside";
  } catch (const std::exception& e) {
    ADD_FAILURE() << name << ": no signed distance field: " << e.what();
  }
}

TEST_F(SceneGeneratorTest, GeometryLibraryLoadsCleanSurfacesWithSignedFields) {
  for (const auto& name : kSurfaces) {
    const fs::path path = *first_ / (name + ".obj");
    try {
      const fahr::geometry::SurfaceMesh surface = fahr::geometry::load_surface(path, kMetresPerMm);
      EXPECT_GT(surface.triangle_count(), 0u) << name;
      expect_clean_and_signed(surface, name);
    } catch (const std::exception& e) {
      ADD_FAILURE() << path << ": " << e.what();
    }
  }
}

TEST_F(SceneGeneratorTest, TongueBoundaryIsCleanWithSignedField) {
  MeshedSolid tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  // Only the nodes the boundary uses, so the surface has no stray vertices.
  std::vector<int> compact(tongue.nodes.size(), -1);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<fahr::geometry::Triangle> triangles;
  for (const auto& f : tongue.boundary) {
    fahr::geometry::Triangle t{};
    for (size_t k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(f[k]);
      ASSERT_LT(v, tongue.nodes.size());
      if (compact[v] < 0) {
        compact[v] = static_cast<int>(vertices.size());
        vertices.push_back(tongue.nodes[v] * kMetresPerMm);
      }
      t[k] = static_cast<fahr::geometry::Index>(compact[v]);
    }
    triangles.push_back(t);
  }
  const fahr::geometry::SurfaceMesh surface(std::move(vertices), std::move(triangles));
  expect_clean_and_signed(surface, "tongue boundary");
}

// The deformable epiglottis: every tet of positive volume and no sliver, a
// closed outward boundary that is the rigid epiglottis.obj's surface (the same
// lattice), held at its base only: the fixed nodes are its lowest, over the
// larynx's anterior rim, and the tip is free.
TEST_F(SceneGeneratorTest, EpiglottisTetsAreTheLeafHeldAtItsBase) {
  MeshedSolid leaf;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "epiglottis").string(), leaf, error)) << error;
  EXPECT_GE(leaf.tets.size(), 1000u);
  EXPECT_GE(fahr::scenegen::tet_quality(leaf).min_dihedral_deg, 15.0);
  expect_valid_tets(leaf);
  const TriangleMesh boundary{leaf.nodes, leaf.boundary};
  TriangleMesh rigid;
  ASSERT_TRUE(fahr::scenegen::read_obj((*first_ / "epiglottis.obj").string(), rigid, error))
      << error;
  EXPECT_NEAR(fahr::scenegen::enclosed_volume(boundary), fahr::scenegen::enclosed_volume(rigid),
              0.02 * fahr::scenegen::enclosed_volume(rigid));
  double lowest = 1e9;
  double highest = -1e9;
  for (const auto& p : leaf.nodes) {
    lowest = std::min(lowest, p.y());
    highest = std::max(highest, p.y());
  }
  std::ifstream file(*first_ / "epiglottis_fixed_nodes.txt");
  std::string line;
  int fixed = 0;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t v = std::stoul(line);
    ASSERT_LT(v, leaf.nodes.size());
    EXPECT_LE(leaf.nodes[v].y(), lowest + 0.5) << "fixed node " << v << " is not at the base";
    ++fixed;
  }
  EXPECT_GE(fixed, 10);
  EXPECT_LT(fixed, static_cast<int>(leaf.nodes.size()) / 4);
  EXPECT_GE(highest - lowest, 8.0) << "the leaf's length";
}

// The body is held only where it meets bone: every fixed node lies on the
// mandible or the hyoid (within the bone gap and the attachment band,
// 1.5 mm), and both hold some.
TEST_F(SceneGeneratorTest, FixedNodesAreAttachedToBone) {
  constexpr double kAttachedWithinMm = 1.5;
  MeshedSolid tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  TriangleMesh jaw;
  TriangleMesh hyoid;
  ASSERT_TRUE(fahr::scenegen::read_obj((*first_ / "jaw.obj").string(), jaw, error)) << error;
  ASSERT_TRUE(fahr::scenegen::read_obj((*first_ / "hyoid.obj").string(), hyoid, error)) << error;
  std::ifstream file(*first_ / "tongue_fixed_nodes.txt");
  std::string line;
  int on_jaw = 0;
  int on_hyoid = 0;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t v = std::stoul(line);
    ASSERT_LT(v, tongue.nodes.size());
    const double to_jaw = fahr::scenegen::distance_to_surface(jaw, tongue.nodes[v]);
    const double to_hyoid = fahr::scenegen::distance_to_surface(hyoid, tongue.nodes[v]);
    EXPECT_LE(std::min(to_jaw, to_hyoid), kAttachedWithinMm) << "fixed node " << v;
    on_jaw += to_jaw <= kAttachedWithinMm ? 1 : 0;
    on_hyoid += to_hyoid <= kAttachedWithinMm ? 1 : 0;
  }
  EXPECT_GT(on_jaw, 0);
  EXPECT_GT(on_hyoid, 0);
}

}  // namespace

namespace {

// An ellipsoid, its value scaled to about a distance in mm near the surface.
class Ellipsoid final : public fahr::scenegen::ImplicitSolid {
 public:
  double value(const Vec3& p) const override {
    return (p.cwiseQuotient(kRadii).norm() - 1.0) * kRadii.minCoeff();
  }
  Vec3 lower_bound() const override { return -kRadii; }
  Vec3 upper_bound() const override { return kRadii; }

 private:
  inline static const Vec3 kRadii{11.0, 7.5, 5.5};
};

}  // namespace

// The snapped Kuhn grid leaves boundary nodes in one or two flattened tets,
// far lighter than the median node; the mesher peels their tets off and
// snaps again until none is left. Without the peel (fraction 0) the same
// ellipsoid has such nodes, so the check can fail.
TEST(TetMesher, ThePeelLeavesNoNodeFarLighterThanTheMedian) {
  const Ellipsoid shape;
  fahr::scenegen::TetMesherSettings settings;
  settings.cell_mm = 1.7;
  settings.grid_turn_z_deg = 17.0;
  const auto light_count = [](const MeshedSolid& mesh, double fraction) {
    const std::vector<double> mass = fahr::scenegen::node_mass_over_median(mesh);
    return std::count_if(mass.begin(), mass.end(), [&](double m) { return m < fraction; });
  };
  settings.min_node_mass_fraction = 0.0;
  fahr::scenegen::TetMesherReport unpeeled_report;
  const MeshedSolid unpeeled =
      fahr::scenegen::mesh_implicit_solid(shape, settings, unpeeled_report);
  EXPECT_GT(light_count(unpeeled, 0.1), 0);
  EXPECT_EQ(unpeeled_report.peeled_tets, 0);

  settings.min_node_mass_fraction = 0.1;
  fahr::scenegen::TetMesherReport report;
  const MeshedSolid peeled = fahr::scenegen::mesh_implicit_solid(shape, settings, report);
  EXPECT_GT(report.peeled_tets, 0);
  EXPECT_EQ(light_count(peeled, 0.1), report.light_nodes);
  EXPECT_EQ(report.light_nodes, 0);
  EXPECT_EQ(report.nonmanifold_boundary_edges, 0);
  for (const auto& t : peeled.tets) {
    ASSERT_GT(fahr::scenegen::tet_signed_volume(peeled.nodes[t[0]], peeled.nodes[t[1]],
                                                peeled.nodes[t[2]], peeled.nodes[t[3]]),
              0.0);
  }
  // The peel takes spikes, not the body: the snapped mesh still fills the
  // ellipsoid (4/3 pi abc) within a few per cent, and loses under 1 % of
  // the unpeeled mesh's volume.
  const auto volume = [](const MeshedSolid& mesh) {
    double sum = 0.0;
    for (const auto& t : mesh.tets) {
      sum += fahr::scenegen::tet_signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]],
                                               mesh.nodes[t[3]]);
    }
    return sum;
  };
  const double exact = 4.0 / 3.0 * std::acos(-1.0) * 11.0 * 7.5 * 5.5;
  EXPECT_NEAR(volume(peeled) / exact, 1.0, 0.05);
  EXPECT_GT(volume(peeled), 0.99 * volume(unpeeled));
  std::printf(
      "[ info ] ellipsoid: %zu -> %zu tets, %d peeled, light nodes %ld -> %ld, volume / exact "
      "%.4f -> %.4f\n",
      unpeeled.tets.size(), peeled.tets.size(), report.peeled_tets,
      static_cast<long>(light_count(unpeeled, 0.1)), static_cast<long>(light_count(peeled, 0.1)),
      volume(unpeeled) / exact, volume(peeled) / exact);
}
