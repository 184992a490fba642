// The fixed-node file: comments, blank lines, index base, bad lines.
#include "fahr/scene/node_index_file.h"

#include <gtest/gtest.h>

#include "fahr/scene/scene_error.h"
#include "test_support.h"

namespace fahr::scene::test {
namespace {

TEST(NodeIndexFile, ReadsIndicesSortedAndUnique) {
  TempDir dir;
  const auto file = dir.write("fixed.txt", "# base of the tongue\n12\n\n  3  # a comment\n7\n3\n");
  EXPECT_EQ(read_node_index_file(file, 0), (std::vector<std::uint32_t>{3, 7, 12}));
  EXPECT_EQ(read_node_index_file(file, 1), (std::vector<std::uint32_t>{2, 6, 11}));
}

TEST(NodeIndexFile, BadLinesNameFileAndLine) {
  TempDir dir;
  const auto bad = dir.write("bad.txt", "1\n2\nthree\n");
  try {
    read_node_index_file(bad, 0);
    FAIL() << "expected a SceneError";
  } catch (const SceneError& error) {
    EXPECT_EQ(std::string(error.what()),
              bad.string() + ":3: expected one non-negative node index, got 'three'");
  }
  const auto zero = dir.write("zero.txt", "0\n");
  EXPECT_THROW(read_node_index_file(zero, 1), SceneError);
  EXPECT_THROW(read_node_index_file(dir.path() / "absent.txt", 0), SceneError);
  const auto negative = dir.write("negative.txt", "-4\n");
  EXPECT_THROW(read_node_index_file(negative, 0), SceneError);
}

TEST(NodeIndexFile, SceneReportsTheFileErrorAtTheSceneKey) {
  TempDir dir;
  dir.write("tongue.node", "");
  dir.write("tongue.ele", "");
  dir.write("blade.obj", "");
  dir.write("palate.obj", "");
  dir.write("jaw.stl", "");
  dir.write("fixed.txt", "5\nfive\n");
  const std::string text = replaced("    unit: mm\n  - name: blade",
                                    "    unit: mm\n    fixed:\n      nodes_file: fixed.txt\n"
                                    "  - name: blade");
  try {
    parse_scene(text, "test.yaml", dir.path());
    FAIL() << "expected a SceneError";
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("test.yaml:9:19: bodies[0].fixed.nodes_file: " +
                           (dir.path() / "fixed.txt").string() + ":2: expected one"),
              std::string::npos)
        << message;
  }
}

}  // namespace
}  // namespace fahr::scene::test
