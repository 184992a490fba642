#include "fahr/fem/supernodal_numeric.h"

#include <cblas.h>

#include <algorithm>
#include <cstring>

// LAPACK's Cholesky of a dense block (the reference interface; the
// library behind it is the BLAS the system chose, OpenBLAS on a station).
// NOLINTNEXTLINE(readability-identifier-naming): the Fortran symbol
extern "C" void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);

namespace fahr::fem {

namespace {

template <typename T>
std::vector<T> copy_of(std::span<const T> s) {
  return {s.begin(), s.end()};
}

}  // namespace

template <typename Update>
void SupernodalNumeric::for_each_update(std::size_t s, Update update) {
  const int end = super_[s + 1];
  for (int d = head_[s]; d >= 0;) {
    const auto du = std::size_t(d);
    const int d_next = next_[du];
    const int first = row_start_[du] + next_row_[du];
    int last = first;
    while (last < row_start_[du + 1] && rows_[std::size_t(last)] < end) ++last;
    update(d, first, last);
    next_row_[du] = last - row_start_[du];
    link(d);
    d = d_next;
  }
  head_[s] = -1;
}

void SupernodalNumeric::link_below(std::size_t s) {
  next_row_[s] = super_[s + 1] - super_[s];
  link(int(s));
}

void SupernodalNumeric::link(int d) {
  const auto du = std::size_t(d);
  const int position = row_start_[du] + next_row_[du];
  if (position >= row_start_[du + 1]) return;  // no rows left below
  const auto t = std::size_t(column_supernode_[std::size_t(rows_[std::size_t(position)])]);
  next_[du] = head_[t];
  head_[t] = d;
}

std::string SupernodalNumeric::prepare(const SupernodalPattern& pattern,
                                       std::span<const int> column_start,
                                       std::span<const int> row_index) {
  map_.clear();
  if (pattern.super.size() < 2 || pattern.row_start.size() != pattern.super.size() ||
      pattern.value_start.size() != pattern.super.size()) {
    return "supernodal pattern: super, row_start and value_start must have nsuper + 1 entries";
  }
  super_ = copy_of(pattern.super);
  row_start_ = copy_of(pattern.row_start);
  rows_ = copy_of(pattern.rows);
  value_start_ = copy_of(pattern.value_start);
  const std::size_t nsuper = super_.size() - 1;
  const auto n = static_cast<std::size_t>(super_.back());
  if (pattern.perm.size() != n || column_start.size() != n + 1)
    return "supernodal pattern: the permutation and A must have as many columns as L";
  if (static_cast<std::size_t>(row_start_.back()) != rows_.size())
    return "supernodal pattern: row_start does not end at the row count";

  column_supernode_.assign(n, 0);
  for (std::size_t k = 0; k < nsuper; ++k) {
    for (int c = super_[k]; c < super_[k + 1]; ++c) column_supernode_[std::size_t(c)] = int(k);
  }
  std::vector<int> position(n, 0);
  for (std::size_t k = 0; k < n; ++k) position[std::size_t(pattern.perm[k])] = int(k);

  // A's entry (i, j), i <= j, is L's entry (max, min) of the permuted
  // indices; its row is found among its supernode's sorted rows.
  map_.assign(row_index.size(), -1);
  for (std::size_t j = 0; j < n; ++j) {
    for (int p = column_start[j]; p < column_start[j + 1]; ++p) {
      const auto i = static_cast<std::size_t>(row_index[std::size_t(p)]);
      if (i > j) continue;
      const int a = position[i];
      const int b = position[j];
      const int row = std::max(a, b);
      const int column = std::min(a, b);
      const int k = column_supernode_[std::size_t(column)];
      const int* first = rows_.data() + row_start_[std::size_t(k)];
      const int* last = rows_.data() + row_start_[std::size_t(k) + 1];
      const int* found = std::lower_bound(first, last, row);
      if (found == last || *found != row) {
        map_.clear();
        return "supernodal pattern: A has an entry outside L's structure (another pattern?)";
      }
      const std::int64_t rows_k = last - first;
      map_[std::size_t(p)] = value_start_[std::size_t(k)] +
                             std::int64_t{column - super_[std::size_t(k)]} * rows_k +
                             (found - first);
    }
  }

  // One dry run of the descendant lists sizes the update block.
  head_.assign(nsuper, -1);
  next_.assign(nsuper, -1);
  next_row_.assign(nsuper, 0);
  local_.assign(n, 0);
  std::size_t largest_update = 1;
  for (std::size_t s = 0; s < nsuper; ++s) {
    for_each_update(s, [&](int d, int first, int last) {
      const auto all = std::size_t(row_start_[std::size_t(d) + 1] - first);
      largest_update = std::max(largest_update, all * std::size_t(last - first));
    });
    link_below(s);
  }
  update_.assign(largest_update, 0.0);
  return "";
}

bool SupernodalNumeric::factorize(std::span<const double> values, std::span<double> l_values) {
  if (map_.empty() || values.size() != map_.size() ||
      l_values.size() < static_cast<std::size_t>(value_start_.back()))
    return false;
  std::memset(l_values.data(), 0, sizeof(double) * static_cast<std::size_t>(value_start_.back()));
  for (std::size_t p = 0; p < map_.size(); ++p) {
    if (map_[p] >= 0) l_values[std::size_t(map_[p])] = values[p];
  }
  double* const l = l_values.data();
  const int* const rows = rows_.data();
  const std::size_t nsuper = super_.size() - 1;
  std::fill(head_.begin(), head_.end(), -1);
  for (std::size_t s = 0; s < nsuper; ++s) {
    const int k1 = super_[s];
    const int k2 = super_[s + 1];
    const int s_first = row_start_[s];
    const int s_rows = row_start_[s + 1] - s_first;
    const int s_columns = k2 - k1;
    double* const block = l + value_start_[s];
    for (int i = 0; i < s_rows; ++i) local_[std::size_t(rows[s_first + i])] = i;

    // Every supernode whose rows reach into [k1, k2) subtracts its share.
    for_each_update(s, [&](int d, int first, int last) {
      const auto du = std::size_t(d);
      const int d_rows = row_start_[du + 1] - row_start_[du];
      const int d_columns = super_[du + 1] - super_[du];
      const int above = last - first;              // rows in this supernode's columns
      const int all = row_start_[du + 1] - first;  // those and every row below them
      const double* const top = l + value_start_[du] + (first - row_start_[du]);
      double* const c = update_.data();
      cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, above, d_columns, 1.0, top, d_rows, 0.0,
                  c, all);
      if (all > above) {
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, all - above, above, d_columns, 1.0,
                    top + above, d_rows, top, d_rows, 0.0, c + above, all);
      }
      for (int j = 0; j < above; ++j) {
        double* const column = block + std::ptrdiff_t{rows[first + j] - k1} * s_rows;
        const double* const cj = c + std::ptrdiff_t{j} * all;
        for (int i = j; i < all; ++i) column[local_[std::size_t(rows[first + i])]] -= cj[i];
      }
    });

    int info = 0;
    dpotrf_("L", &s_columns, block, &s_rows, &info);
    if (info != 0) {
      failed_column_ = std::size_t(k1 + info - 1);
      return false;
    }
    if (s_rows > s_columns) {
      cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit,
                  s_rows - s_columns, s_columns, 1.0, block, s_rows, block + s_columns, s_rows);
    }
    link_below(s);
  }
  return true;
}

}  // namespace fahr::fem
