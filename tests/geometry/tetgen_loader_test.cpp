// TetGen loader: valid files (0- and 1-based, mm, .face markers) and every error class.
#include "fahr/geometry/tetgen_loader.h"

#include <gtest/gtest.h>

#include "mesh_text.h"
#include "test_support.h"

namespace fahr::geometry {
namespace {

constexpr double kMm = 0.001;

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  ASSERT_EQ(a.node_count(), b.node_count());
  ASSERT_EQ(a.tets(), b.tets());
  for (std::size_t n = 0; n < a.node_count(); ++n) {
    EXPECT_TRUE(a.rest_positions()[n].isApprox(b.rest_positions()[n], 1e-15)) << "node " << n;
  }
}

TEST(TetgenLoader, RoundTripZeroAndOneBasedInMillimetres) {
  const TetMesh cube = test::cube_tets(2, 0.005);
  test::TempDir dir;
  for (int first : {0, 1}) {
    const std::string stem = "cube" + std::to_string(first);
    dir.write(stem + ".node", test::tetgen_node_text(cube, first, kMm));
    dir.write(stem + ".ele", test::tetgen_ele_text(cube, first));
    expect_same_mesh(load_tetgen(dir.path() / (stem + ".node"), kMm), cube);
    expect_same_mesh(load_tetgen(dir.path() / stem, kMm), cube);
  }
}

TEST(TetgenLoader, FaceMarkersAreAttached) {
  const TetMesh cube = test::cube_tets(1, 1.0);
  test::TempDir dir;
  dir.write("c.node", test::tetgen_node_text(cube, 0, 1.0));
  dir.write("c.ele", test::tetgen_ele_text(cube, 0));
  const Triangle& f = cube.boundary_faces()[3].nodes;
  // Face listed in another node order, with a marker and -nn adjacency fields.
  dir.write("c.face", "1 1\n0 " + std::to_string(f[2]) + " " + std::to_string(f[0]) + " " +
                          std::to_string(f[1]) + " 7 -1 0\n");
  const TetMesh mesh = load_tetgen(dir.path() / "c.ele", 1.0);
  int marked = 0;
  for (const BoundaryFace& face : mesh.boundary_faces()) {
    marked += face.marker == 7 ? 1 : 0;
  }
  EXPECT_EQ(marked, 1);
}

struct TetgenCase {
  const char* name;
  const char* node;
  const char* ele;
  const char* bad_file;  // "node" or "ele"
  int line;
  std::vector<std::string> fragments;
};

class TetgenErrors : public ::testing::TestWithParam<TetgenCase> {};

TEST_P(TetgenErrors, NameFileLineAndItem) {
  const TetgenCase& c = GetParam();
  test::TempDir dir;
  const auto node = dir.write("m.node", c.node);
  const auto ele = dir.write("m.ele", c.ele);
  const std::string bad = std::string(c.bad_file) == "node" ? node.string() : ele.string();
  test::expect_load_error([&] { load_tetgen(node, 1.0); }, bad, c.line, c.fragments);
}

constexpr const char* kNodes = "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 0\n";
constexpr const char* kEle = "1 4 0\n0 0 1 2 3\n";

INSTANTIATE_TEST_SUITE_P(
    Malformed, TetgenErrors,
    ::testing::Values(
        TetgenCase{
            "inverted", kNodes, "1 4 0\n0 0 2 1 3\n", "ele", 2, {"tet 0", "non-positive volume"}},
        TetgenCase{"flat",
                   kNodes,
                   "2 4 0\n0 0 1 2 3\n1 0 1 4 2\n",
                   "ele",
                   3,
                   {"tet 1", "non-positive volume"}},
        TetgenCase{"out_of_range",
                   kNodes,
                   "1 4 0\n0 0 1 2 9\n",
                   "ele",
                   2,
                   {"tet 0", "node index 9 out of range"}},
        TetgenCase{
            "negative_index", kNodes, "1 4 0\n0 0 1 -1 3\n", "ele", 2, {"tet 0", "out of range"}},
        TetgenCase{"nan",
                   "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 nan 0\n3 0 0 1\n",
                   kEle,
                   "node",
                   4,
                   {"node 2", "non-finite"}},
        TetgenCase{"inf",
                   "4 3 0 0\n0 0 0 0\n1 inf 0 0\n2 0 1 0\n3 0 0 1\n",
                   kEle,
                   "node",
                   3,
                   {"node 1", "non-finite"}},
        TetgenCase{"quadratic",
                   kNodes,
                   "1 10 0\n0 0 1 2 3 0 0 0 0 0 0\n",
                   "ele",
                   1,
                   {"unsupported element type", "10 nodes"}},
        TetgenCase{"truncated_nodes",
                   "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1",
                   kEle,
                   "node",
                   4,
                   {"unexpected end of file", "node 2"}},
        TetgenCase{"truncated_ele",
                   kNodes,
                   "2 4 0\n0 0 1 2 3\n1 0 1",
                   "ele",
                   3,
                   {"unexpected end of file", "tet 1"}},
        TetgenCase{"garbage",
                   "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1x\n",
                   kEle,
                   "node",
                   5,
                   {"expected a number", "node 3", "'1x'"}},
        TetgenCase{
            "extra_field", kNodes, "1 4 0\n0 0 1 2 3 4\n", "ele", 2, {"extra field", "tet 0"}},
        TetgenCase{"bad_first_index",
                   "4 3 0 0\n5 0 0 0\n6 1 0 0\n7 0 1 0\n8 0 0 1\n",
                   kEle,
                   "node",
                   2,
                   {"first node index"}},
        TetgenCase{"gap_in_numbering",
                   "4 3 0 0\n0 0 0 0\n1 1 0 0\n3 0 1 0\n4 0 0 1\n",
                   kEle,
                   "node",
                   4,
                   {"node 3", "expected node index 2"}}),
    [](const ::testing::TestParamInfo<TetgenCase>& param_info) {
      return std::string(param_info.param.name);
    });

TEST(TetgenLoader, MissingFileIsNamed) {
  test::TempDir dir;
  const auto node = dir.path() / "absent.node";
  test::expect_load_error([&] { load_tetgen(node, 1.0); }, node.string(), 0, {"cannot open"});
}

TEST(TetgenLoader, ParsesFromMemory) {
  const TetMesh mesh = parse_tetgen({kNodes, "mem.node"}, {kEle, "mem.ele"}, {"", "mem.face"}, 1.0);
  EXPECT_EQ(mesh.tet_count(), 1u);
  EXPECT_EQ(mesh.quality().unreferenced_node_count, 1u);
}

}  // namespace
}  // namespace fahr::geometry
