// Gmsh .msh reader, formats 1, 2 (ASCII) and 4 (ASCII, 4.0 and 4.1), from the
// Gmsh reference manual's "MSH file format" section and its legacy-format appendix.
#include "fahr/geometry/gmsh_loader.h"

#include <string>
#include <unordered_map>
#include <vector>

#include "fahr/geometry/load_error.h"
#include "gmsh_element_types.h"
#include "loader_support.h"
#include "token_reader.h"

namespace fahr::geometry {
namespace {

using detail::Token;
using detail::TokenReader;

constexpr std::size_t kMinNodeRecordBytes = 8;  // "1 0 0 0\n"

// Version 4.1 changed the block headers of 4.0 (entity dim first, min/max tags).
constexpr double kFirstVersion41 = 4.05;

enum class Format { kUnknown, kV1, kV2, kV40, kV41 };

class GmshParser {
 public:
  GmshParser(const TextSource& source, double scale_to_m)
      : reader_(source.text, source.name, '\0'), name_(source.name), scale_(scale_to_m) {}

  TetMesh parse() {
    Token token;
    while (reader_.next(token)) {
      if (token.text == "$MeshFormat") {
        read_format(token);
      } else if (token.text == "$NOD") {
        format_ = Format::kV1;
        read_nodes_v1v2("$ENDNOD");
      } else if (token.text == "$ELM") {
        format_ = Format::kV1;
        read_elements_v1v2("$ENDELM");
      } else if (token.text == "$Nodes") {
        require_format(token);
        if (format_ == Format::kV2) {
          read_nodes_v1v2("$EndNodes");
        } else {
          read_nodes_v4();
        }
      } else if (token.text == "$Elements") {
        require_format(token);
        if (format_ == Format::kV2) {
          read_elements_v1v2("$EndElements");
        } else {
          read_elements_v4();
        }
      } else if (token.text.size() > 1 && token.text.front() == '$') {
        // Any other section ($PhysicalNames, $Entities, $NodeData, ...) is not needed.
        reader_.skip_to("$End" + std::string(token.text.substr(1)));
      } else {
        reader_.fail(token.line, "expected a section keyword such as $Nodes, found " +
                                     detail::quote(token.text));
      }
    }
    if (tets_.empty()) {
      throw LoadError(name_, 0, "no linear tetrahedra (element type 4) in the file");
    }
    return detail::make_tet_mesh(std::move(nodes_), std::move(tets_), name_);
  }

 private:
  void read_format(const Token& start) {
    const Token version_token = reader_.expect("format version");
    double version = 0.0;
    if (!detail::parse_double(version_token.text, version)) {
      reader_.fail(version_token.line,
                   "expected a format version, found " + detail::quote(version_token.text));
    }
    const std::int64_t file_type = reader_.expect_int("file type");
    reader_.expect_int("data size");
    if (file_type != 0) {
      reader_.fail(start.line, "binary .msh files are not supported (file type " +
                                   std::to_string(file_type) + "); save as ASCII");
    }
    if (version >= 2.0 && version < 3.0) {
      format_ = Format::kV2;
    } else if (version >= 4.0 && version < kFirstVersion41) {
      format_ = Format::kV40;
    } else if (version >= kFirstVersion41 && version < 5.0) {
      format_ = Format::kV41;
    } else {
      reader_.fail(version_token.line, "unsupported .msh version " +
                                           std::string(version_token.text) +
                                           " (supported: 1, 2.x, 4.0, 4.1)");
    }
    expect_keyword("$EndMeshFormat");
  }

  void require_format(const Token& token) {
    if (format_ == Format::kUnknown || format_ == Format::kV1) {
      reader_.fail(token.line, std::string(token.text) + " before $MeshFormat");
    }
  }

  void expect_keyword(std::string_view keyword) {
    const Token token = reader_.expect(keyword);
    if (token.text != keyword) {
      reader_.fail(token.line,
                   "expected " + std::string(keyword) + ", found " + detail::quote(token.text));
    }
  }

  std::int64_t read_tag(const std::string& what, int* line = nullptr) {
    const Token token = reader_.expect(what);
    std::int64_t tag = 0;
    if (!detail::parse_int(token.text, tag)) {
      reader_.fail(token.line,
                   "expected an integer for " + what + ", found " + detail::quote(token.text));
    }
    if (line != nullptr) {
      *line = token.line;
    }
    return tag;
  }

  void add_node(std::int64_t tag, int line) {
    const std::string what = "node " + std::to_string(tag);
    const auto [it, inserted] = node_index_.emplace(tag, static_cast<Index>(nodes_.size()));
    if (!inserted) {
      reader_.fail(line, what + ": duplicate node tag");
    }
    nodes_.push_back(detail::read_position(reader_, scale_, what));
  }

  Index node_ref(const std::string& what) {
    int line = 0;
    const std::int64_t tag = read_tag("a node of " + what, &line);
    const auto it = node_index_.find(tag);
    if (it == node_index_.end()) {
      reader_.fail(line,
                   what + ": node tag " + std::to_string(tag) + " out of range (no such node)");
    }
    return it->second;
  }

  // An element of `type` with its tag read: keeps a linear tet, skips lower-dimensional elements.
  void read_element_nodes(std::int64_t tag, std::int64_t type, int line) {
    const std::string what = "element " + std::to_string(tag);
    const detail::GmshElementType info = detail::gmsh_element_type(type);
    if (info.dimension < 0 || (info.dimension == 3 && type != detail::kGmshLinearTet)) {
      reader_.fail(line, what + ": unsupported element type " + std::to_string(type) +
                             " (only linear tetrahedra, type 4, and lower-dimensional elements)");
    }
    if (type != detail::kGmshLinearTet) {
      for (int n = 0; n < info.node_count; ++n) {
        node_ref(what);
      }
      return;
    }
    Tet tet{};
    for (Index& n : tet) {
      n = node_ref(what);
    }
    detail::check_tet_volume(nodes_, tet, reader_, line, what);
    tets_.push_back(tet);
  }

  void read_nodes_v1v2(std::string_view end_keyword) {
    const std::int64_t count = detail::read_count(reader_, "node count");
    nodes_.reserve(detail::reserve_bound(count, reader_.remaining_bytes(), kMinNodeRecordBytes));
    for (std::int64_t n = 0; n < count; ++n) {
      int line = 0;
      const std::int64_t tag =
          read_tag("node " + std::to_string(n) + " of " + std::to_string(count), &line);
      add_node(tag, line);
      reader_.expect_end_of_line(line, "node " + std::to_string(tag));
    }
    expect_keyword(end_keyword);
  }

  void read_elements_v1v2(std::string_view end_keyword) {
    const std::int64_t count = detail::read_count(reader_, "element count");
    for (std::int64_t e = 0; e < count; ++e) {
      int line = 0;
      const std::int64_t tag =
          read_tag("element " + std::to_string(e) + " of " + std::to_string(count), &line);
      const std::string what = "element " + std::to_string(tag);
      const std::int64_t type = reader_.expect_int("type of " + what);
      if (format_ == Format::kV1) {
        reader_.expect_int("physical region of " + what);
        reader_.expect_int("elementary region of " + what);
        const std::int64_t node_count = reader_.expect_int("node count of " + what);
        const detail::GmshElementType info = detail::gmsh_element_type(type);
        if (info.dimension >= 0 && node_count != info.node_count) {
          reader_.fail(line, what + ": type " + std::to_string(type) + " has " +
                                 std::to_string(info.node_count) + " nodes, the file says " +
                                 std::to_string(node_count));
        }
      } else {
        const std::int64_t tag_count = detail::read_count(reader_, "tag count of " + what);
        for (std::int64_t t = 0; t < tag_count; ++t) {
          reader_.expect_int("tag of " + what);
        }
      }
      read_element_nodes(tag, type, line);
      reader_.expect_end_of_line(line, what);
    }
    expect_keyword(end_keyword);
  }

  void read_nodes_v4() {
    const std::int64_t blocks = detail::read_count(reader_, "node block count");
    const std::int64_t count = detail::read_count(reader_, "node count");
    if (format_ == Format::kV41) {
      reader_.expect_int("minimum node tag");
      reader_.expect_int("maximum node tag");
    }
    nodes_.reserve(detail::reserve_bound(count, reader_.remaining_bytes(), kMinNodeRecordBytes));
    for (std::int64_t b = 0; b < blocks; ++b) {
      const std::string block = "node block " + std::to_string(b);
      std::int64_t dimension = 0;
      if (format_ == Format::kV41) {
        dimension = reader_.expect_int("entity dimension of " + block);
        reader_.expect_int("entity tag of " + block);
      } else {
        reader_.expect_int("entity tag of " + block);
        dimension = reader_.expect_int("entity dimension of " + block);
      }
      const std::int64_t parametric = reader_.expect_int("parametric flag of " + block);
      const std::int64_t in_block = detail::read_count(reader_, "node count of " + block);
      // Parametric nodes carry one coordinate per dimension of their entity after x y z.
      const std::int64_t extra = parametric != 0 ? dimension : 0;
      if (format_ == Format::kV41) {
        std::vector<std::pair<std::int64_t, int>> tags;
        tags.reserve(detail::reserve_bound(in_block, reader_.remaining_bytes(), 2));
        for (std::int64_t n = 0; n < in_block; ++n) {
          int line = 0;
          const std::int64_t tag =
              read_tag("node tag " + std::to_string(n) + " of " + block, &line);
          tags.emplace_back(tag, line);
        }
        for (const auto& [tag, line] : tags) {
          add_node(tag, line);
          skip_parametric(extra, tag);
        }
      } else {
        for (std::int64_t n = 0; n < in_block; ++n) {
          int line = 0;
          const std::int64_t tag = read_tag("node " + std::to_string(n) + " of " + block, &line);
          add_node(tag, line);
          skip_parametric(extra, tag);
        }
      }
    }
    expect_keyword("$EndNodes");
  }

  void skip_parametric(std::int64_t extra, std::int64_t tag) {
    for (std::int64_t i = 0; i < extra; ++i) {
      reader_.expect_finite("parametric coordinate of node " + std::to_string(tag));
    }
  }

  void read_elements_v4() {
    const std::int64_t blocks = detail::read_count(reader_, "element block count");
    detail::read_count(reader_, "element count");
    if (format_ == Format::kV41) {
      reader_.expect_int("minimum element tag");
      reader_.expect_int("maximum element tag");
    }
    for (std::int64_t b = 0; b < blocks; ++b) {
      const std::string block = "element block " + std::to_string(b);
      reader_.expect_int("entity of " + block);
      reader_.expect_int("entity of " + block);
      const std::int64_t type = reader_.expect_int("element type of " + block);
      const std::int64_t in_block = detail::read_count(reader_, "element count of " + block);
      for (std::int64_t e = 0; e < in_block; ++e) {
        int line = 0;
        const std::int64_t tag = read_tag("element " + std::to_string(e) + " of " + block, &line);
        read_element_nodes(tag, type, line);
        reader_.expect_end_of_line(line, "element " + std::to_string(tag));
      }
    }
    expect_keyword("$EndElements");
  }

  TokenReader reader_;
  std::string_view name_;
  double scale_;
  Format format_ = Format::kUnknown;
  std::vector<Eigen::Vector3d> nodes_;
  std::vector<Tet> tets_;
  std::unordered_map<std::int64_t, Index> node_index_;
};

}  // namespace

TetMesh parse_gmsh(const TextSource& source, double scale_to_m) {
  detail::check_scale(scale_to_m, source.name);
  return GmshParser(source, scale_to_m).parse();
}

TetMesh load_gmsh(const std::filesystem::path& path, double scale_to_m) {
  const std::string name = path.string();
  const std::string text = read_text_file(name);
  return parse_gmsh({text, name}, scale_to_m);
}

}  // namespace fahr::geometry
