// The numeric half of a supernodal Cholesky factorisation L L' = P A P' on
// a symbolic structure computed once (CHOLMOD's supernodal analysis: the
// fill-reducing permutation, the supernodes, their row indices and where
// their value blocks start). Left-looking, as CHOLMOD's own numeric
// factorisation: a supernode gathers the updates of the supernodes below it
// in the elimination tree (one SYRK and one GEMM each), then factorises its
// diagonal block (POTRF) and solves the rows under it (TRSM).
//
// What it leaves out is what a refactorisation on a fixed pattern does not
// need: CHOLMOD 3 permutes and transposes A on every call, allocates and
// frees its workspace, and opens OpenMP regions; here A's entries go
// straight to their places in L through a map built once, and every buffer
// is sized once, so a factorisation allocates nothing. On the neonatal
// tongue (5,175 unknowns, 0.97 M non-zeros in L) it takes about 60 % of
// cholmod_factorize's time with the same BLAS (docs/design/fem-step-and-solvers.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fahr::fem {

// A supernodal structure in CHOLMOD's layout (int indices): supernode k
// holds columns [super[k], super[k + 1]) of L, its row indices are
// rows[row_start[k], row_start[k + 1]) (ascending, its own columns first),
// and its values a column-major block of (row count) x (column count) at
// value_start[k]. perm[k] is the original row of row k of P A P'.
struct SupernodalPattern {
  std::span<const int> super;
  std::span<const int> row_start;
  std::span<const int> rows;
  std::span<const int> value_start;
  std::span<const int> perm;
};

class SupernodalNumeric {
 public:
  // Builds the map from A's stored entries to L's values and sizes every
  // buffer. A is symmetric, compressed by column with its upper triangle
  // stored (row <= column; entries below the diagonal are ignored, as
  // CHOLMOD ignores them for stype 1); its pattern must be the one the
  // structure was analysed for. Returns "" or what does not fit.
  std::string prepare(const SupernodalPattern& pattern, std::span<const int> column_start,
                      std::span<const int> row_index);

  bool prepared() const { return !map_.empty(); }

  // Writes L's values (value_start[nsuper] of them) for A's `values` (in
  // the order of the entries given to prepare). False, with L partly
  // written, if A is not positive definite; `failed_column` then names the
  // column of P A P' where it was found.
  bool factorize(std::span<const double> values, std::span<double> l_values);

  std::size_t failed_column() const { return failed_column_; }

 private:
  std::vector<int> super_, row_start_, rows_, value_start_;
  std::vector<int> column_supernode_;
  // map_[k]: the index in L's values of A's stored entry k, or -1 (below
  // the diagonal: ignored).
  std::vector<std::int64_t> map_;
  // Per factorisation: the supernodes waiting to update each supernode
  // (head_/next_ lists), where each one's next unused row is, the local row
  // of each row in the supernode being assembled, and the update block.
  std::vector<int> head_, next_, next_row_, local_;

  // Calls update(d, first, last) for each supernode d in s's list, with
  // rows_[first, last) its unused rows in s's columns, then moves d to the
  // list of the supernode its next row falls in.
  template <typename Update>
  void for_each_update(std::size_t s, Update update);
  // Once s is factorised: into the list of the supernode of its first row
  // below the diagonal block.
  void link_below(std::size_t s);
  void link(int d);
  std::vector<double> update_;
  std::size_t failed_column_ = 0;
};

}  // namespace fahr::fem
