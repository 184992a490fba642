// Legacy VTK reader ("VTK File Formats", VTK User's Guide; the 5.1 variant
// stores cells as OFFSETS and CONNECTIVITY arrays).
#include "fahr/geometry/vtk_loader.h"

#include <string>
#include <vector>

#include "fahr/geometry/load_error.h"
#include "loader_support.h"
#include "token_reader.h"

namespace fahr::geometry {
namespace {

using detail::Token;
using detail::TokenReader;

constexpr std::int64_t kVtkTetra = 10;
constexpr std::size_t kMinValueBytes = 2;  // "0 "

// Cell types of dimension 0-2 (vertex, poly-vertex, line, poly-line,
// triangle, strip, polygon, pixel, quad, and the quadratic edge, triangle and quad).
bool is_lower_dimensional_cell(std::int64_t type) {
  return (type >= 1 && type <= 9) || (type >= 21 && type <= 23);
}

std::string_view next_line(std::string_view text, std::size_t& pos) {
  const std::size_t end = text.find('\n', pos);
  const std::size_t stop = end == std::string_view::npos ? text.size() : end;
  std::string_view line = text.substr(pos, stop - pos);
  pos = end == std::string_view::npos ? text.size() : end + 1;
  if (!line.empty() && line.back() == '\r') {
    line.remove_suffix(1);
  }
  return line;
}

class VtkParser {
 public:
  VtkParser(const TextSource& source, double scale_to_m) : source_(source), scale_(scale_to_m) {}

  TetMesh parse() {
    // The first three lines are not token streams: a magic line, a free-text title, the encoding.
    std::size_t pos = 0;
    const std::string_view magic = next_line(source_.text, pos);
    if (magic.rfind("# vtk DataFile Version", 0) != 0) {
      throw LoadError(source_.name, 1, "not a legacy VTK file (expected '# vtk DataFile Version')");
    }
    next_line(source_.text, pos);  // title
    if (pos >= source_.text.size()) {
      throw LoadError(source_.name, 2, "unexpected end of file after the title");
    }
    TokenReader reader(source_.text.substr(pos), source_.name, '\0', 3);
    const Token encoding = reader.expect("the encoding (ASCII)");
    if (encoding.text != "ASCII") {
      reader.fail(encoding.line,
                  "unsupported encoding " + detail::quote(encoding.text) + " (only ASCII)");
    }
    const Token dataset = reader.expect("DATASET");
    const Token kind = reader.expect("the dataset type");
    if (dataset.text != "DATASET" || kind.text != "UNSTRUCTURED_GRID") {
      reader.fail(dataset.line, "expected 'DATASET UNSTRUCTURED_GRID', found " +
                                    detail::quote(dataset.text) + " " + detail::quote(kind.text));
    }
    read_sections(reader);
    return build(reader);
  }

 private:
  void read_sections(TokenReader& reader) {
    Token token;
    while (reader.next(token)) {
      if (token.text == "POINTS") {
        read_points(reader);
      } else if (token.text == "CELLS") {
        read_cells(reader, token);
      } else if (token.text == "CELL_TYPES") {
        read_cell_types(reader);
      } else if (token.text == "FIELD") {
        skip_field(reader);
      } else if (token.text == "POINT_DATA" || token.text == "CELL_DATA") {
        return;  // attributes follow; the geometry is complete
      } else {
        reader.fail(token.line,
                    "unexpected keyword " + detail::quote(token.text) +
                        " (expected POINTS, CELLS, CELL_TYPES, FIELD, POINT_DATA or CELL_DATA)");
      }
    }
  }

  void read_points(TokenReader& reader) {
    const std::int64_t count = detail::read_count(reader, "point count");
    reader.expect("point data type");
    nodes_.reserve(detail::reserve_bound(count, reader.remaining_bytes(), 3 * kMinValueBytes));
    for (std::int64_t n = 0; n < count; ++n) {
      nodes_.push_back(detail::read_position(reader, scale_, "point " + std::to_string(n)));
    }
  }

  void read_cells(TokenReader& reader, const Token& keyword) {
    cells_line_ = keyword.line;
    const std::int64_t first = detail::read_count(reader, "cell count");
    const std::int64_t second = detail::read_count(reader, "cell list size");
    Token next;
    if (reader.peek(next) && next.text == "OFFSETS") {
      read_cells_51(reader, first, second);
      return;
    }
    const std::size_t reserve =
        detail::reserve_bound(first, reader.remaining_bytes(), kMinValueBytes);
    offsets_.reserve(reserve + 1);
    offsets_.push_back(0);
    std::int64_t used = 0;
    for (std::int64_t c = 0; c < first; ++c) {
      Token count_token;
      reader.peek(count_token);
      const std::int64_t size =
          detail::read_count(reader, "point count of cell " + std::to_string(c));
      used += size + 1;
      if (used > second) {
        reader.fail(count_token.line, "cell " + std::to_string(c) +
                                          ": the cell list is longer than the " +
                                          std::to_string(second) + " values CELLS announced");
      }
      cell_lines_.push_back(count_token.line);
      for (std::int64_t k = 0; k < size; ++k) {
        connectivity_.push_back(reader.expect_int("a point of cell " + std::to_string(c)));
      }
      offsets_.push_back(static_cast<std::int64_t>(connectivity_.size()));
    }
  }

  void read_cells_51(TokenReader& reader, std::int64_t offset_count,
                     std::int64_t connectivity_count) {
    reader.expect("OFFSETS");
    reader.expect("offset data type");
    if (offset_count < 1) {
      reader.fail(cells_line_, "CELLS needs at least one offset");
    }
    offsets_.reserve(detail::reserve_bound(offset_count, reader.remaining_bytes(), kMinValueBytes));
    for (std::int64_t i = 0; i < offset_count; ++i) {
      Token t;
      reader.peek(t);
      const std::int64_t offset = reader.expect_int("offset " + std::to_string(i));
      if (offset < (offsets_.empty() ? 0 : offsets_.back()) || offset > connectivity_count ||
          (i == 0 && offset != 0)) {
        reader.fail(t.line, "offset " + std::to_string(i) + " = " + std::to_string(offset) +
                                " is not a non-decreasing index into the connectivity list of " +
                                std::to_string(connectivity_count));
      }
      offsets_.push_back(offset);
      if (i > 0) {
        cell_lines_.push_back(t.line);
      }
    }
    const Token keyword = reader.expect("CONNECTIVITY");
    if (keyword.text != "CONNECTIVITY") {
      reader.fail(keyword.line, "expected CONNECTIVITY, found " + detail::quote(keyword.text));
    }
    reader.expect("connectivity data type");
    connectivity_.reserve(
        detail::reserve_bound(connectivity_count, reader.remaining_bytes(), kMinValueBytes));
    for (std::int64_t i = 0; i < connectivity_count; ++i) {
      Token t;
      reader.peek(t);
      connectivity_.push_back(reader.expect_int("connectivity entry " + std::to_string(i)));
      // Cells are reported at the line where their points are.
      const auto cell =
          static_cast<std::size_t>(std::upper_bound(offsets_.begin(), offsets_.end(), i) -
                                   offsets_.begin()) -
          1;
      if (cell < cell_lines_.size() && i == offsets_[cell]) {
        cell_lines_[cell] = t.line;
      }
    }
    if (offsets_.back() != connectivity_count) {
      reader.fail(cells_line_, "the last offset " + std::to_string(offsets_.back()) +
                                   " differs from the " + std::to_string(connectivity_count) +
                                   " connectivity entries");
    }
  }

  void read_cell_types(TokenReader& reader) {
    const std::int64_t count = detail::read_count(reader, "cell type count");
    types_.reserve(detail::reserve_bound(count, reader.remaining_bytes(), kMinValueBytes));
    for (std::int64_t c = 0; c < count; ++c) {
      Token t;
      reader.peek(t);
      types_.emplace_back(reader.expect_int("type of cell " + std::to_string(c)), t.line);
    }
  }

  // FIELD name n, then n arrays "name components tuples type" with components * tuples values.
  void skip_field(TokenReader& reader) {
    reader.expect("field name");
    const std::int64_t arrays = detail::read_count(reader, "field array count");
    for (std::int64_t a = 0; a < arrays; ++a) {
      reader.expect("field array name");
      const std::int64_t components = detail::read_count(reader, "field component count");
      const std::int64_t tuples = detail::read_count(reader, "field tuple count");
      reader.expect("field data type");
      for (std::int64_t v = 0; v < components * tuples; ++v) {
        reader.expect("field value");
      }
    }
  }

  TetMesh build(const TokenReader& reader) {
    const std::size_t cell_count = offsets_.empty() ? 0 : offsets_.size() - 1;
    if (types_.size() != cell_count) {
      throw LoadError(source_.name, cells_line_,
                      "CELL_TYPES lists " + std::to_string(types_.size()) + " types for " +
                          std::to_string(cell_count) + " cells");
    }
    const auto node_count = static_cast<std::int64_t>(nodes_.size());
    std::vector<Tet> tets;
    for (std::size_t c = 0; c < cell_count; ++c) {
      const auto [type, type_line] = types_[c];
      const int line = c < cell_lines_.size() ? cell_lines_[c] : type_line;
      const std::string what = "cell " + std::to_string(c);
      if (is_lower_dimensional_cell(type)) {
        continue;
      }
      if (type != kVtkTetra) {
        reader.fail(type_line,
                    what + ": unsupported cell type " + std::to_string(type) + " (only 10, tetra)");
      }
      const std::int64_t begin = offsets_[c];
      const std::int64_t size = offsets_[c + 1] - begin;
      if (size != 4) {
        reader.fail(line, what + ": a tetra needs 4 points, the cell has " + std::to_string(size));
      }
      Tet tet{};
      for (std::size_t k = 0; k < 4; ++k) {
        const std::int64_t id = connectivity_[static_cast<std::size_t>(begin) + k];
        if (id < 0 || id >= node_count) {
          reader.fail(line, what + ": point index " + std::to_string(id) + " out of range [0, " +
                                std::to_string(node_count) + ")");
        }
        tet[k] = static_cast<Index>(id);
      }
      detail::check_tet_volume(nodes_, tet, reader, line, what);
      tets.push_back(tet);
    }
    if (tets.empty()) {
      throw LoadError(source_.name, 0, "no tetra cells (type 10) in the file");
    }
    return detail::make_tet_mesh(std::move(nodes_), std::move(tets), source_.name);
  }

  TextSource source_;
  double scale_;
  int cells_line_ = 0;
  std::vector<Eigen::Vector3d> nodes_;
  std::vector<std::int64_t> offsets_;
  std::vector<std::int64_t> connectivity_;
  std::vector<int> cell_lines_;
  std::vector<std::pair<std::int64_t, int>> types_;  // type, line
};

}  // namespace

TetMesh parse_vtk(const TextSource& source, double scale_to_m) {
  detail::check_scale(scale_to_m, source.name);
  return VtkParser(source, scale_to_m).parse();
}

TetMesh load_vtk(const std::filesystem::path& path, double scale_to_m) {
  const std::string name = path.string();
  const std::string text = read_text_file(name);
  return parse_vtk({text, name}, scale_to_m);
}

}  // namespace fahr::geometry
