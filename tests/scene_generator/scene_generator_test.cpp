// Runs fahr_scene_generator twice with its defaults and checks that both runs
// and the committed meshes/neonatal files are byte-identical (so what is
// committed is exactly the generator's output), that every tet has positive
// volume and that every surface is closed and outward oriented.
#include "fahr/scenegen/mesh_checks.h"
#include "fahr/scenegen/mesh_readers.h"

#include <gtest/gtest.h>

#include <stdlib.h>  // mkdtemp (POSIX)

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using fahr::scenegen::TetMesh;
using fahr::scenegen::TriangleMesh;

#ifndef FAHR_SCENE_GENERATOR
#error "FAHR_SCENE_GENERATOR must name the generator executable"
#endif

const std::vector<std::string> kSceneFiles = {
    "tongue.node", "tongue.ele", "tongue.face", "tongue_fixed_nodes.txt",
    "palate.obj",  "jaw.obj",    "lips_face.obj", "larynx_trachea.obj",
    "miller0.obj", "miller1.obj", "scene_parameters.txt"};
const std::vector<std::string> kSurfaces = {"palate", "jaw", "lips_face", "larynx_trachea",
                                            "miller0", "miller1"};

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
  const fs::path dir = pattern;
  const std::string command = std::string("\"") + FAHR_SCENE_GENERATOR + "\" --out \"" +
                              dir.string() + "\" > \"" + (dir / "generator.log").string() + "\"";
  EXPECT_EQ(std::system(command.c_str()), 0) << "generator failed; see " << dir / "generator.log";
  return dir;
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

TEST_F(SceneGeneratorTest, TetsHavePositiveVolumeAndBoundaryIsClosed) {
  TetMesh tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  EXPECT_GE(tongue.tets.size(), 2000u);
  EXPECT_LE(tongue.tets.size(), 6000u);
  for (size_t i = 0; i < tongue.tets.size(); ++i) {
    const auto& t = tongue.tets[i];
    for (const int v : t) ASSERT_LT(static_cast<size_t>(v), tongue.nodes.size()) << "tet " << i;
    EXPECT_GT(fahr::scenegen::tet_signed_volume(tongue.nodes[t[0]], tongue.nodes[t[1]],
                                                tongue.nodes[t[2]], tongue.nodes[t[3]]),
              0.0)
        << "tet " << i;
  }
  const TriangleMesh boundary{tongue.nodes, tongue.boundary};
  const auto closed = fahr::scenegen::check_closed(boundary);
  EXPECT_TRUE(closed.closed_and_oriented())
      << closed.bad_edges << " bad, " << closed.inconsistent_edges << " inconsistent edges";
  EXPECT_GT(fahr::scenegen::enclosed_volume(boundary), 0.0) << "boundary not outward";
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

TEST_F(SceneGeneratorTest, FixedNodesAreTongueNodes) {
  TetMesh tongue;
  std::string error;
  ASSERT_TRUE(fahr::scenegen::read_tetgen((*first_ / "tongue").string(), tongue, error)) << error;
  std::ifstream file(*first_ / "tongue_fixed_nodes.txt");
  std::string line;
  int count = 0;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    EXPECT_LT(std::stoul(line), tongue.nodes.size());
    ++count;
  }
  EXPECT_GT(count, 0);
}

}  // namespace
