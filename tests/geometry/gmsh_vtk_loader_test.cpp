// Gmsh (v1, v2, v4.1) and legacy VTK (3.0 and 5.1) loaders: valid files and every error class.
#include <gtest/gtest.h>

#include "fahr/geometry/gmsh_loader.h"
#include "fahr/geometry/tet_mesh_loader.h"
#include "fahr/geometry/vtk_loader.h"
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

TEST(GmshLoader, RoundTripEveryVersion) {
  const TetMesh cube = test::cube_tets(2, 0.004);
  test::TempDir dir;
  expect_same_mesh(load_gmsh(dir.write("v1.msh", test::gmsh_v1_text(cube, kMm)), kMm), cube);
  expect_same_mesh(load_gmsh(dir.write("v2.msh", test::gmsh_v2_text(cube, kMm)), kMm), cube);
  expect_same_mesh(load_gmsh(dir.write("v41.msh", test::gmsh_v41_text(cube, kMm)), kMm), cube);
}

TEST(GmshLoader, Version40Blocks) {
  // 4.0: block header "entity-tag dim parametric count", one "tag x y z" line per node.
  const std::string text =
      "$MeshFormat\n4 0 8\n$EndMeshFormat\n$Nodes\n1 4\n1 3 0 4\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 "
      "0 0 1\n"
      "$EndNodes\n$Elements\n1 1\n1 3 4 1\n5 10 20 30 40\n$EndElements\n";
  const TetMesh mesh = parse_gmsh({text, "v40.msh"}, 1.0);
  EXPECT_EQ(mesh.tet_count(), 1u);
  EXPECT_NEAR(mesh.quality().total_volume_m3, 1.0 / 6.0, 1e-15);
}

struct TextCase {
  const char* name;
  std::string text;
  int line;
  std::vector<std::string> fragments;
};

const std::string kV2Head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const std::string kV2Nodes = "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 0\n$EndNodes\n";

class GmshErrors : public ::testing::TestWithParam<TextCase> {};

TEST_P(GmshErrors, NameFileLineAndElement) {
  const TextCase& c = GetParam();
  test::TempDir dir;
  const auto file = dir.write("bad.msh", c.text);
  test::expect_load_error([&] { load_gmsh(file, 1.0); }, file.string(), c.line, c.fragments);
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, GmshErrors,
    ::testing::Values(
        // Lines: 1-3 format, 4 $Nodes, 5 count, 6-10 nodes, 11 $EndNodes, 12 $Elements, 13
        // count, 14.. elements.
        TextCase{"inverted",
                 kV2Head + kV2Nodes + "$Elements\n1\n7 4 0 1 3 2 4\n$EndElements\n",
                 14,
                 {"element 7", "non-positive volume"}},
        TextCase{"flat",
                 kV2Head + kV2Nodes + "$Elements\n1\n7 4 0 1 2 5 3\n$EndElements\n",
                 14,
                 {"element 7", "non-positive volume"}},
        TextCase{"unknown_tag",
                 kV2Head + kV2Nodes + "$Elements\n1\n7 4 0 1 2 3 99\n$EndElements\n",
                 14,
                 {"element 7", "node tag 99 out of range"}},
        TextCase{"nan", kV2Head + "$Nodes\n1\n1 0 nan 0\n$EndNodes\n", 6, {"node 1", "non-finite"}},
        TextCase{"hexahedron",
                 kV2Head + kV2Nodes + "$Elements\n1\n3 5 0 1 2 3 4 5 1 2 3\n$EndElements\n",
                 14,
                 {"element 3", "unsupported element type 5"}},
        TextCase{"unknown_type",
                 kV2Head + kV2Nodes + "$Elements\n1\n3 77 0 1\n$EndElements\n",
                 14,
                 {"element 3", "unsupported element type 77"}},
        TextCase{"truncated",
                 kV2Head + kV2Nodes + "$Elements\n2\n7 4 0 1 2 3 4\n8 4 0 1 2",
                 15,
                 {"unexpected end of file", "element 8"}},
        TextCase{"missing_end",
                 kV2Head + kV2Nodes + "$Elements\n1\n7 4 0 1 2 3 4\n",
                 14,
                 {"unexpected end of file", "$EndElements"}},
        TextCase{"garbage_coordinate",
                 kV2Head + "$Nodes\n1\n1 0 0 zz\n$EndNodes\n",
                 6,
                 {"expected a number", "node 1", "'zz'"}},
        TextCase{"garbage_line", kV2Head + "hello\n", 4, {"section keyword", "'hello'"}},
        TextCase{"duplicate_tag",
                 kV2Head + "$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n",
                 7,
                 {"node 1", "duplicate"}},
        TextCase{"binary", "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n", 1, {"binary"}},
        TextCase{"v1_wrong_count",
                 "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n1\n1 4 1 1 3 1 2 "
                 "3\n$ENDELM\n",
                 10,
                 {"element 1", "has 4 nodes"}}),
    [](const ::testing::TestParamInfo<TextCase>& param_info) {
      return std::string(param_info.param.name);
    });

TEST(VtkLoader, RoundTripLegacyAnd51) {
  const TetMesh cube = test::cube_tets(2, 0.004);
  test::TempDir dir;
  expect_same_mesh(load_vtk(dir.write("a.vtk", test::vtk_text(cube, kMm)), kMm), cube);
  expect_same_mesh(load_vtk(dir.write("b.vtk", test::vtk51_text(cube, kMm)), kMm), cube);
}

const std::string kVtkHead =
    "# vtk DataFile Version 3.0\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n"
    "0 0 0 1 0 0 0 1 0\n0 0 1 1 1 0\n";  // lines 1-7

class VtkErrors : public ::testing::TestWithParam<TextCase> {};

TEST_P(VtkErrors, NameFileLineAndCell) {
  const TextCase& c = GetParam();
  test::TempDir dir;
  const auto file = dir.write("bad.vtk", c.text);
  test::expect_load_error([&] { load_vtk(file, 1.0); }, file.string(), c.line, c.fragments);
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, VtkErrors,
    ::testing::Values(
        TextCase{"inverted",
                 kVtkHead + "CELLS 1 5\n4 0 2 1 3\nCELL_TYPES 1\n10\n",
                 9,
                 {"cell 0", "non-positive volume"}},
        TextCase{"flat",
                 kVtkHead + "CELLS 2 10\n4 0 1 2 3\n4 0 1 4 2\nCELL_TYPES 2\n10\n10\n",
                 10,
                 {"cell 1", "non-positive volume"}},
        TextCase{"out_of_range",
                 kVtkHead + "CELLS 1 5\n4 0 1 2 5\nCELL_TYPES 1\n10\n",
                 9,
                 {"cell 0", "point index 5 out of range"}},
        TextCase{"nan",
                 "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 "
                 "float\n0 NaN 0\n",
                 6,
                 {"point 0", "non-finite"}},
        TextCase{"hexahedron",
                 kVtkHead + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n12\n",
                 11,
                 {"cell 0", "unsupported cell type 12"}},
        TextCase{"truncated",
                 kVtkHead + "CELLS 2 10\n4 0 1 2 3\n4 0 1",
                 10,
                 {"unexpected end of file", "cell 1"}},
        TextCase{"garbage",
                 kVtkHead + "CELLS 1 5\n4 0 1 two 3\nCELL_TYPES 1\n10\n",
                 9,
                 {"expected an integer", "cell 0", "'two'"}},
        TextCase{"binary", "# vtk DataFile Version 3.0\nt\nBINARY\n", 3, {"unsupported encoding"}},
        TextCase{"not_vtk", "hello\n", 1, {"not a legacy VTK file"}},
        TextCase{"type_count",
                 kVtkHead + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10\n10\n",
                 8,
                 {"CELL_TYPES lists 2"}}),
    [](const ::testing::TestParamInfo<TextCase>& param_info) {
      return std::string(param_info.param.name);
    });

}  // namespace
}  // namespace fahr::geometry

namespace fahr::geometry {
namespace {

TEST(TetMeshLoader, DispatchesByExtension) {
  const TetMesh cube = test::cube_tets(1, 0.01);
  test::TempDir dir;
  EXPECT_EQ(load_tet_mesh(dir.write("a.msh", test::gmsh_v2_text(cube, 1.0)), 1.0).tet_count(), 6u);
  EXPECT_EQ(load_tet_mesh(dir.write("a.vtk", test::vtk_text(cube, 1.0)), 1.0).tet_count(), 6u);
  dir.write("t.1.node", test::tetgen_node_text(cube, 1, 1.0));
  dir.write("t.1.ele", test::tetgen_ele_text(cube, 1));
  EXPECT_EQ(load_tet_mesh(dir.path() / "t.1", 1.0).tet_count(), 6u);
  EXPECT_EQ(load_tet_mesh(dir.path() / "t.1.ele", 1.0).tet_count(), 6u);
  const auto other = dir.write("a.off", "OFF\n");
  test::expect_load_error([&] { load_tet_mesh(other, 1.0); }, other.string(), 0,
                          {"unknown tet-mesh format"});
}

}  // namespace
}  // namespace fahr::geometry
