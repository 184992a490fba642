// TetGen .node/.ele/.face reader (file formats of the TetGen manual, 1.5, section 5.2).
#include "fahr/geometry/tetgen_loader.h"

#include <string>
#include <vector>

#include "fahr/geometry/load_error.h"
#include "loader_support.h"
#include "token_reader.h"

namespace fahr::geometry {
namespace {

using detail::Token;
using detail::TokenReader;

// Smallest byte counts of one record ("0 0 0 0\n", "0 0 0 0 0\n"), to bound reservations.
constexpr std::size_t kMinNodeRecordBytes = 8;
constexpr std::size_t kMinTetRecordBytes = 10;

struct NodeTable {
  std::vector<Eigen::Vector3d> positions;  // m
  std::int64_t first_index = 0;            // 0 or 1, from the first node line
};

NodeTable read_nodes(const TextSource& source, double scale_to_m) {
  TokenReader reader(source.text, source.name, '#');
  const Token first = [&] {
    Token t;
    if (!reader.peek(t)) {
      reader.fail(1, "empty .node file");
    }
    return t;
  }();
  const std::int64_t count = detail::read_count(reader, "node count");
  const std::int64_t dimension = reader.expect_int("dimension");
  const std::int64_t attributes = detail::read_count(reader, "attribute count");
  const std::int64_t markers = reader.expect_int("boundary marker flag");
  if (count == 0) {
    reader.fail(first.line, "node count 0: nodes stored in a .poly file are not supported");
  }
  if (dimension != 3) {
    reader.fail(first.line, "dimension " + std::to_string(dimension) + " (only 3 is supported)");
  }
  if (markers != 0 && markers != 1) {
    reader.fail(first.line, "boundary marker flag must be 0 or 1, got " + std::to_string(markers));
  }
  reader.expect_end_of_line(first.line, "the .node header");
  NodeTable table;
  table.positions.reserve(
      detail::reserve_bound(count, reader.remaining_bytes(), kMinNodeRecordBytes));
  for (std::int64_t n = 0; n < count; ++n) {
    const Token id_token =
        reader.expect("node " + std::to_string(n) + " of " + std::to_string(count));
    std::int64_t id = 0;
    if (!detail::parse_int(id_token.text, id)) {
      reader.fail(id_token.line, "expected a node index, found " + detail::quote(id_token.text));
    }
    if (n == 0) {
      if (id != 0 && id != 1) {
        reader.fail(id_token.line, "first node index must be 0 or 1, got " + std::to_string(id));
      }
      table.first_index = id;
    } else if (id != table.first_index + n) {
      reader.fail(id_token.line, "node " + std::to_string(id) + ": expected node index " +
                                     std::to_string(table.first_index + n) +
                                     " (nodes must be numbered consecutively)");
    }
    const std::string what = "node " + std::to_string(id);
    table.positions.push_back(detail::read_position(reader, scale_to_m, what));
    for (std::int64_t a = 0; a < attributes + markers; ++a) {
      reader.expect_finite("attribute or marker of " + what);
    }
    reader.expect_end_of_line(id_token.line, what);
  }
  Token extra;
  if (reader.peek(extra)) {
    reader.fail(extra.line,
                "unexpected data " + detail::quote(extra.text) + " after the last node");
  }
  return table;
}

Index read_node_ref(TokenReader& reader, const NodeTable& nodes, const std::string& what) {
  const Token token = reader.expect("a node of " + what);
  std::int64_t id = 0;
  if (!detail::parse_int(token.text, id)) {
    reader.fail(token.line, what + ": expected a node index, found " + detail::quote(token.text));
  }
  const std::int64_t index = id - nodes.first_index;
  const auto count = static_cast<std::int64_t>(nodes.positions.size());
  if (index < 0 || index >= count) {
    reader.fail(token.line, what + ": node index " + std::to_string(id) + " out of range [" +
                                std::to_string(nodes.first_index) + ", " +
                                std::to_string(nodes.first_index + count) + ")");
  }
  return static_cast<Index>(index);
}

std::vector<Tet> read_tets(const TextSource& source, const NodeTable& nodes) {
  TokenReader reader(source.text, source.name, '#');
  Token header;
  if (!reader.peek(header)) {
    reader.fail(1, "empty .ele file");
  }
  const std::int64_t count = detail::read_count(reader, "tet count");
  const std::int64_t per_tet = reader.expect_int("nodes per tet");
  const std::int64_t attributes = detail::read_count(reader, "region attribute count");
  if (per_tet != 4) {
    reader.fail(header.line, "unsupported element type: " + std::to_string(per_tet) +
                                 " nodes per tet (only linear 4-node tets are supported)");
  }
  reader.expect_end_of_line(header.line, "the .ele header");
  std::vector<Tet> tets;
  tets.reserve(detail::reserve_bound(count, reader.remaining_bytes(), kMinTetRecordBytes));
  for (std::int64_t t = 0; t < count; ++t) {
    const Token id_token =
        reader.expect("tet " + std::to_string(t) + " of " + std::to_string(count));
    std::int64_t id = 0;
    if (!detail::parse_int(id_token.text, id)) {
      reader.fail(id_token.line, "expected a tet index, found " + detail::quote(id_token.text));
    }
    const std::string what = "tet " + std::to_string(id);
    Tet tet{};
    for (Index& n : tet) {
      n = read_node_ref(reader, nodes, what);
    }
    for (std::int64_t a = 0; a < attributes; ++a) {
      reader.expect_finite("region attribute of " + what);
    }
    reader.expect_end_of_line(id_token.line, what);
    detail::check_tet_volume(nodes.positions, tet, reader, id_token.line, what);
    tets.push_back(tet);
  }
  Token extra;
  if (reader.peek(extra)) {
    reader.fail(extra.line, "unexpected data " + detail::quote(extra.text) + " after the last tet");
  }
  return tets;
}

void read_faces(const TextSource& source, const NodeTable& nodes, std::vector<Triangle>& faces,
                std::vector<int>& markers) {
  TokenReader reader(source.text, source.name, '#');
  Token header;
  if (!reader.peek(header)) {
    reader.fail(1, "empty .face file");
  }
  const std::int64_t count = detail::read_count(reader, "face count");
  const std::int64_t has_markers = reader.expect_int("boundary marker flag");
  if (has_markers != 0 && has_markers != 1) {
    reader.fail(header.line,
                "boundary marker flag must be 0 or 1, got " + std::to_string(has_markers));
  }
  reader.expect_end_of_line(header.line, "the .face header");
  faces.reserve(detail::reserve_bound(count, reader.remaining_bytes(), kMinNodeRecordBytes));
  for (std::int64_t f = 0; f < count; ++f) {
    const Token id_token =
        reader.expect("face " + std::to_string(f) + " of " + std::to_string(count));
    std::int64_t id = 0;
    if (!detail::parse_int(id_token.text, id)) {
      reader.fail(id_token.line, "expected a face index, found " + detail::quote(id_token.text));
    }
    const std::string what = "face " + std::to_string(id);
    Triangle face{};
    for (Index& n : face) {
      n = read_node_ref(reader, nodes, what);
    }
    std::int64_t marker = 0;
    if (has_markers == 1) {
      marker = reader.expect_int("boundary marker of " + what);
    }
    // TetGen's -nn switch appends the two adjacent tets: allowed, not used.
    reader.skip_line(id_token.line);
    faces.push_back(face);
    markers.push_back(static_cast<int>(marker));
  }
}

}  // namespace

TetMesh parse_tetgen(const TextSource& node, const TextSource& ele, const TextSource& face,
                     double scale_to_m) {
  detail::check_scale(scale_to_m, node.name);
  const NodeTable nodes = read_nodes(node, scale_to_m);
  std::vector<Tet> tets = read_tets(ele, nodes);
  std::vector<Triangle> faces;
  std::vector<int> markers;
  if (!face.text.empty()) {
    read_faces(face, nodes, faces, markers);
  }
  TetMesh mesh = detail::make_tet_mesh(nodes.positions, std::move(tets), ele.name);
  if (!faces.empty()) {
    mesh.assign_boundary_markers(faces, markers);
  }
  return mesh;
}

TetMesh load_tetgen(const std::filesystem::path& path, double scale_to_m) {
  std::filesystem::path stem = path;
  if (stem.extension() == ".node" || stem.extension() == ".ele" || stem.extension() == ".face") {
    stem.replace_extension();
  }
  const std::string node_path = stem.string() + ".node";
  const std::string ele_path = stem.string() + ".ele";
  const std::string face_path = stem.string() + ".face";
  const std::string node_text = read_text_file(node_path);
  const std::string ele_text = read_text_file(ele_path);
  std::string face_text;
  if (std::filesystem::exists(face_path)) {
    face_text = read_text_file(face_path);
  }
  return parse_tetgen({node_text, node_path}, {ele_text, ele_path}, {face_text, face_path},
                      scale_to_m);
}

}  // namespace fahr::geometry
