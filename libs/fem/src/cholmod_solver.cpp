// CHOLMOD through its C API (not Eigen's wrapper) so that solves can reuse
// their output and workspace buffers (cholmod_solve2) and allocate nothing.
#include "fahr/fem/cholmod_solver.h"

#include <cholmod.h>

#include <algorithm>
#include <array>
#include <cstring>

namespace fahr::fem {

struct CholmodSolver::State {
  cholmod_common common{};
  cholmod_sparse view{};  // borrows the arrays of the caller's matrix
  cholmod_factor* factor = nullptr;
  // Reused by cholmod_solve2: X (result), Y and E (workspace). CHOLMOD
  // reallocates them whenever the column count changes, so each count in use
  // keeps its own set: single solves (CG, the step) and the compliance
  // block's full and chunked solves then alternate without allocating.
  struct Buffers {
    cholmod_dense* x = nullptr;
    cholmod_dense* y = nullptr;
    cholmod_dense* e = nullptr;
    int columns = 0;             // 0: unused
    std::uint64_t last_use = 0;  // for replacing the least recently used set
  };
  std::array<Buffers, CholmodSolver::kColumnCounts> sets{};
  std::uint64_t uses = 0;
  std::uint64_t factorisations = 0;
  bool numeric = false;
  std::size_t rows = 0;

  // The set kept for this column count, else the least recently used one
  // (whose buffers CHOLMOD will reallocate to the new shape).
  Buffers& buffers_for(int columns) {
    Buffers* chosen = &sets[0];
    for (Buffers& b : sets) {
      if (b.columns == columns) {
        chosen = &b;
        break;
      }
      if (b.last_use < chosen->last_use) chosen = &b;
    }
    chosen->columns = columns;
    chosen->last_use = ++uses;
    return *chosen;
  }

  void release(Buffers& buffers) {
    if (buffers.x != nullptr) cholmod_free_dense(&buffers.x, &common);
    if (buffers.y != nullptr) cholmod_free_dense(&buffers.y, &common);
    if (buffers.e != nullptr) cholmod_free_dense(&buffers.e, &common);
  }

  ~State() {
    if (factor != nullptr) cholmod_free_factor(&factor, &common);
    for (Buffers& b : sets) release(b);
    cholmod_finish(&common);
  }

  // CHOLMOD 3 (SuiteSparse 5.12) solves simplicial factors four columns at
  // a time in a workspace Y it sizes max(4, columns) x n, then shrinks Y's
  // recorded shape to the columns it used; the next solve sees a "wrong"
  // shape and reallocates. Restoring the shape it asks for (the storage is
  // large enough) keeps solves allocation-free; the no-allocation test
  // checks this against the installed CHOLMOD.
  void restore_simplicial_workspace(cholmod_dense* y, std::size_t columns) const {
    if (y == nullptr || factor == nullptr || factor->is_super != 0) return;
    const std::size_t rows_used = std::max<std::size_t>(4, columns);
    if (y->nzmax < rows_used * rows) return;
    y->nrow = rows_used;
    y->d = rows_used;
    y->ncol = rows;
  }

  void solve_dense(const double* b, double* out, int columns) {
    Buffers& buffers = buffers_for(columns);
    cholmod_dense rhs{};
    rhs.nrow = rows;
    rhs.ncol = static_cast<std::size_t>(columns);
    rhs.nzmax = rows * rhs.ncol;
    rhs.d = rows;
    rhs.x = const_cast<double*>(b);  // CHOLMOD's API is not const-correct; it only reads B
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    restore_simplicial_workspace(buffers.y, rhs.ncol);
    cholmod_solve2(CHOLMOD_A, factor, &rhs, nullptr, &buffers.x, nullptr, &buffers.y, &buffers.e,
                   &common);
    std::memcpy(out, buffers.x->x, sizeof(double) * rows * rhs.ncol);
  }
};

CholmodSolver::CholmodSolver() : state_(std::make_unique<State>()) {
  cholmod_start(&state_->common);
  // Errors are reported through return values and common.status, not printed.
  state_->common.print = 0;
}

CholmodSolver::~CholmodSolver() = default;

bool CholmodSolver::analyze(const SparseMatrix& matrix, const CholmodOptions& options) {
  State& s = *state_;
  switch (options.factor) {
    case CholmodFactorKind::kAuto:
      s.common.supernodal = CHOLMOD_AUTO;
      break;
    case CholmodFactorKind::kSimplicial:
      s.common.supernodal = CHOLMOD_SIMPLICIAL;
      break;
    case CholmodFactorKind::kSupernodal:
      s.common.supernodal = CHOLMOD_SUPERNODAL;
      break;
  }
  if (options.ordering != CholmodOrdering::kDefault) {
    s.common.nmethods = 1;
    s.common.method[0].ordering =
        options.ordering == CholmodOrdering::kAmd ? CHOLMOD_AMD : CHOLMOD_METIS;
    s.common.postorder = 1;
  }
  if (s.factor != nullptr) cholmod_free_factor(&s.factor, &s.common);
  s.numeric = false;
  s.rows = static_cast<std::size_t>(matrix.rows());
  s.view = cholmod_sparse{};
  s.view.nrow = s.rows;
  s.view.ncol = static_cast<std::size_t>(matrix.cols());
  s.view.nzmax = static_cast<std::size_t>(matrix.nonZeros());
  // CHOLMOD reads these arrays only; the casts drop const for its C API.
  s.view.p = const_cast<int*>(matrix.outerIndexPtr());
  s.view.i = const_cast<int*>(matrix.innerIndexPtr());
  s.view.x = const_cast<double*>(matrix.valuePtr());
  s.view.stype = 1;  // symmetric: the upper triangle is used, the lower ignored
  s.view.itype = CHOLMOD_INT;
  s.view.xtype = CHOLMOD_REAL;
  s.view.dtype = CHOLMOD_DOUBLE;
  s.view.sorted = 1;
  s.view.packed = 1;
  s.factor = cholmod_analyze(&s.view, &s.common);
  return s.factor != nullptr && s.common.status >= CHOLMOD_OK;
}

bool CholmodSolver::factorize() {
  State& s = *state_;
  if (s.factor == nullptr) return false;
  const int ok = cholmod_factorize(&s.view, s.factor, &s.common);
  s.numeric = ok != 0 && s.common.status == CHOLMOD_OK;
  if (s.numeric) ++s.factorisations;
  return s.numeric;
}

bool CholmodSolver::factorized() const {
  return state_->numeric;
}

std::uint64_t CholmodSolver::factorisations() const {
  return state_->factorisations;
}

void CholmodSolver::solve(std::span<const double> b, std::span<double> x) {
  state_->solve_dense(b.data(), x.data(), 1);
}

void CholmodSolver::solve_columns(std::span<const double> b, std::span<double> x, int columns) {
  state_->solve_dense(b.data(), x.data(), columns);
}

double CholmodSolver::factor_nonzeros() const {
  return state_->common.lnz;
}

bool CholmodSolver::supernodal() const {
  return state_->factor != nullptr && state_->factor->is_super != 0;
}

}  // namespace fahr::fem
