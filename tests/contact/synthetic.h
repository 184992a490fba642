// Synthetic contact problems without a FEM: a flat patch of n tissue spheres
// under a flat tool, with a compliance W of a diagonal part (local
// stiffness) and a uniform coupling (the patch moving together).
#pragma once

#include <vector>

#include "fahr/contact/contact_row.h"
#include "fahr/contact/tissue_compliance.h"

namespace fahr::contact::test {

struct SyntheticPatch {
  std::vector<std::uint32_t> ids;
  std::vector<float> w;
  std::vector<ContactRow> rows;
  TissueCompliance compliance() const { return TissueCompliance{7, ids, w, {}}; }
};

// n spheres at x = i mm, y = 0, pressed from above by a tool whose face is at
// tool_y; diagonal compliance `local` and coupling `shared` (m/N) along y.
inline SyntheticPatch make_patch(std::size_t n, double tool_y, double local, double shared) {
  SyntheticPatch p;
  const std::size_t rows = 3 * n;
  p.w.assign(rows * rows, 0.0f);
  for (std::size_t s = 0; s < n; ++s) {
    p.ids.push_back(static_cast<std::uint32_t>(s));
    for (std::size_t t = 0; t < n; ++t) {
      for (std::size_t d = 0; d < 3; ++d) {
        const double value = (s == t ? local : 0.0) + shared;
        p.w[(3 * s + d) * rows + 3 * t + d] = static_cast<float>(value);
      }
    }
  }
  for (std::size_t s = 0; s < n; ++s) {
    ContactRow r;
    r.kind = RowKind::kTissue;
    r.id = static_cast<std::uint32_t>(s);
    r.normal = Eigen::Vector3d(0, -1, 0);
    r.other_point_m = Eigen::Vector3d(0.001 * static_cast<double>(s), 0, 0);
    r.tool_point_m = Eigen::Vector3d(0.001 * static_cast<double>(s), tool_y, 0);
    r.radius_m = 0.0;
    r.compliance_index = static_cast<std::int32_t>(s);
    p.rows.push_back(r);
  }
  return p;
}

// Moves the rows' tool points to a tool face at tool_y.
inline void set_tool_height(SyntheticPatch& p, double tool_y) {
  for (ContactRow& r : p.rows) r.tool_point_m.y() = tool_y;
}

}  // namespace fahr::contact::test
