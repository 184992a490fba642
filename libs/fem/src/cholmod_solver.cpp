// CHOLMOD through its C API (not Eigen's wrapper) so that solves can reuse
// their output and workspace buffers (cholmod_solve2) and allocate nothing.
#include "fahr/fem/cholmod_solver.h"

#include <cblas.h>
#include <cholmod.h>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstring>
#include <ctime>
#include <mutex>
#include <thread>
#include <vector>

#include "fahr/fem/step_parts.h"
#include "fahr/fem/supernodal_numeric.h"
#include "fahr/geometry/vector_clones.h"

namespace fahr::fem {

namespace {
// The background factorisation's nice value (the logger's writer has 10).
constexpr int kBackgroundNice = 10;

// A numeric factorisation of `a` into `f`: CHOLMOD's the first time (it
// allocates L's values and makes the factor numeric), `numeric`'s on the
// same structure after that.
bool factorize_into(cholmod_sparse& a, cholmod_factor* f, cholmod_common& common,
                    SupernodalNumeric& numeric) {
  if (numeric.prepared() && f->is_super != 0 && f->is_ll != 0 && f->xtype == CHOLMOD_REAL &&
      f->x != nullptr) {
    const bool ok = numeric.factorize({static_cast<const double*>(a.x), a.nzmax},
                                      {static_cast<double*>(f->x), f->xsize});
    f->minor = ok ? f->n : numeric.failed_column();
    common.status = ok ? CHOLMOD_OK : CHOLMOD_NOT_POSDEF;
    return ok;
  }
  return cholmod_factorize(&a, f, &common) != 0 && common.status == CHOLMOD_OK;
}

// The supernodes L^-1 P b reaches for a b with non-zeros at `dofs`,
// ascending (CholmodSolver::reach), with the given visit marks.
std::size_t tree_reach(const std::vector<int>& column_supernode, const std::vector<int>& parent,
                       const std::vector<int>& position, std::vector<std::uint32_t>& marks,
                       std::uint32_t& mark, std::span<const std::uint32_t> dofs,
                       std::span<int> out) {
  if (++mark == 0) {  // the marks wrapped: start them again
    std::fill(marks.begin(), marks.end(), 0u);
    mark = 1;
  }
  std::size_t count = 0;
  for (const std::uint32_t dof : dofs) {
    int k = column_supernode[std::size_t(position[dof])];
    while (k >= 0 && marks[std::size_t(k)] != mark) {
      marks[std::size_t(k)] = mark;
      out[count++] = k;
      k = parent[std::size_t(k)];
    }
  }
  // Supernodes are numbered children first (CHOLMOD postorders them).
  std::sort(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(count));
  return count;
}

}  // namespace

// One supernode of a supernodal LL' factor: its columns [first, first +
// columns) in the factor's ordering, its block of rows x columns (column-
// major, leading dimension rows: the lower-triangular diagonal block on top,
// the `below` rows under it) and those rows' indices.
struct Supernode {
  std::size_t first;
  std::size_t columns;
  std::size_t rows;
  std::size_t below;
  const double* l;
  const int* below_rows;
};

Supernode supernode(const cholmod_factor& f, std::size_t k) {
  const int* super = static_cast<const int*>(f.super);
  const int* pi = static_cast<const int*>(f.pi);
  const int* px = static_cast<const int*>(f.px);
  Supernode s{};
  s.first = std::size_t(super[k]);
  s.columns = std::size_t(super[k + 1]) - s.first;
  s.rows = std::size_t(pi[k + 1] - pi[k]);
  s.below = s.rows - s.columns;
  s.l = static_cast<const double*>(f.x) + px[k];
  s.below_rows = static_cast<const int*>(f.s) + pi[k] + static_cast<std::ptrdiff_t>(s.columns);
  return s;
}

// Y := L^-1 Y on the supernodes in `reach` (CholmodSolver::forward3_on_reach)
// for the factor f of n rows, with `update` as the below-diagonal buffer.
// External linkage: target_clones makes an ifunc of it.
FAHR_VECTOR_CLONES void forward3_on_factor(const cholmod_factor& f, std::size_t n,
                                           std::vector<double>& update, std::span<const int> reach,
                                           std::span<double> y) {
  double* y0 = y.data();
  double* y1 = y0 + n;
  double* y2 = y1 + n;
  const std::size_t room = update.size() / 3;
  double* u0 = update.data();
  double* u1 = u0 + room;
  double* u2 = u1 + room;
  for (const int k : reach) {
    const Supernode node = supernode(f, std::size_t(k));
    const std::size_t first = node.first;
    const std::size_t columns = node.columns;
    const std::size_t rows_k = node.rows;
    const std::size_t below = node.below;
    const double* l = node.l;
    double* x0 = y0 + first;
    double* x1 = y1 + first;
    double* x2 = y2 + first;
    std::fill(u0, u0 + below, 0.0);
    std::fill(u1, u1 + below, 0.0);
    std::fill(u2, u2 + below, 0.0);
    for (std::size_t c = 0; c < columns; ++c) {
      const double* lc = l + c * rows_k;
      const double inv = 1.0 / lc[c];
      const double a0 = x0[c] *= inv;
      const double a1 = x1[c] *= inv;
      const double a2 = x2[c] *= inv;
      for (std::size_t r = c + 1; r < columns; ++r) {
        x0[r] -= lc[r] * a0;
        x1[r] -= lc[r] * a1;
        x2[r] -= lc[r] * a2;
      }
      const double* lb = lc + columns;
      for (std::size_t r = 0; r < below; ++r) {
        u0[r] += lb[r] * a0;
        u1[r] += lb[r] * a1;
        u2[r] += lb[r] * a2;
      }
    }
    for (std::size_t r = 0; r < below; ++r) {
      const auto row = std::size_t(node.below_rows[r]);
      y0[row] -= u0[r];
      y1[row] -= u1[r];
      y2[row] -= u2[r];
    }
  }
}

// x := L^-1 x on the supernodes in `reach` (ascending), for one column in
// the factor's ordering that is zero outside them; `update` holds one
// supernode's update of the rows below its diagonal block.
void forward_on_reach(const cholmod_factor& f, std::vector<double>& update,
                      std::span<const int> reach, double* x) {
  double* u = update.data();
  for (const int k : reach) {
    const Supernode n = supernode(f, std::size_t(k));
    double* xs = x + n.first;
    const auto m = static_cast<int>(n.columns);
    const auto ld = static_cast<int>(n.rows);
    cblas_dtrsv(CblasColMajor, CblasLower, CblasNoTrans, CblasNonUnit, m, n.l, ld, xs, 1);
    if (n.below == 0) continue;
    cblas_dgemv(CblasColMajor, CblasNoTrans, static_cast<int>(n.below), m, 1.0, n.l + n.columns, ld,
                xs, 1, 0.0, u, 1);
    for (std::size_t r = 0; r < n.below; ++r) x[n.below_rows[r]] -= u[r];
  }
}

// x := L^-T x, in place, over every supernode of f (last to first), x in the
// factor's ordering; `gather` holds one supernode's rows below its diagonal
// block. The backward half of a dense solve, for right-hand sides whose
// forward half ran on their reach (CholmodSolver::solve_sparse).
void backward_on_factor(const cholmod_factor& f, std::vector<double>& gather, double* x) {
  double* xb = gather.data();
  for (std::size_t k = f.nsuper; k-- > 0;) {
    const Supernode n = supernode(f, k);
    for (std::size_t r = 0; r < n.below; ++r) xb[r] = x[n.below_rows[r]];
    double* xs = x + n.first;
    const auto m = static_cast<int>(n.columns);
    const auto ld = static_cast<int>(n.rows);
    if (n.below > 0) {
      cblas_dgemv(CblasColMajor, CblasTrans, static_cast<int>(n.below), m, -1.0, n.l + n.columns,
                  ld, xb, 1, 1.0, xs, 1);
    }
    cblas_dtrsv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, m, n.l, ld, xs, 1);
  }
}

// Room in `work` for `groups` spheres' panels on the supernodal factor f:
// its widest supernode's columns and deepest rows below one.
void size_panels(const cholmod_factor& f, std::size_t groups, PanelWorkspace& work) {
  const int* super = static_cast<const int*>(f.super);
  const int* pi = static_cast<const int*>(f.pi);
  std::size_t widest = 1;
  std::size_t deepest = 1;
  for (std::size_t k = 0; k < f.nsuper; ++k) {
    const auto columns = std::size_t(super[k + 1] - super[k]);
    widest = std::max(widest, columns);
    deepest = std::max(deepest, std::size_t(pi[k + 1] - pi[k]) - columns);
  }
  const std::size_t width = 3 * groups;
  if (work.panel.size() < widest * width) work.panel.resize(widest * width);
  if (work.below.size() < deepest * width) work.below.resize(deepest * width);
  if (work.gram.size() < width * width) work.gram.resize(width * width);
  if (work.cursor.size() < groups) work.cursor.resize(groups);
  if (work.active.size() < groups) work.active.resize(groups);
}

// forward_gram_on_reach on the factor f of n rows (see the header).
void forward_gram_on_factor(const cholmod_factor& f, std::size_t n,
                            std::span<const HalfSolveColumns> groups, PanelWorkspace& work,
                            std::span<double> gram) {
  const std::size_t count = groups.size();
  const std::size_t width = 3 * count;
  std::fill(gram.begin(), gram.begin() + static_cast<std::ptrdiff_t>(width * width), 0.0);
  if (count == 0) return;
  size_panels(f, count, work);  // nothing if reserve_panels() made room
  std::fill(work.cursor.begin(), work.cursor.begin() + static_cast<std::ptrdiff_t>(count), 0);
  double* panel = work.panel.data();
  double* below_update = work.below.data();
  double* panel_gram = work.gram.data();
  for (std::size_t k = 0; k < f.nsuper; ++k) {
    std::size_t active = 0;
    for (std::size_t g = 0; g < count; ++g) {
      const HalfSolveColumns& group = groups[g];
      if (work.cursor[g] < group.count && std::size_t(group.reach[work.cursor[g]]) == k) {
        work.active[active++] = g;
        ++work.cursor[g];
      }
    }
    if (active == 0) continue;
    const Supernode node = supernode(f, k);
    const std::size_t first = node.first;
    const std::size_t columns = node.columns;
    const std::size_t below = node.below;
    const int panel_columns = static_cast<int>(3 * active);
    const int m = static_cast<int>(columns);
    const int ld = static_cast<int>(node.rows);
    const double* l = node.l;
    // The panel: the active columns' rows of this supernode, column-major.
    for (std::size_t a = 0; a < active; ++a) {
      for (std::size_t d = 0; d < 3; ++d) {
        const double* from = groups[work.active[a]].y + d * n + first;
        std::copy(from, from + columns, panel + (3 * a + d) * columns);
      }
    }
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, m, panel_columns,
                1.0, l, ld, panel, m);
    if (below > 0) {
      cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, static_cast<int>(below), panel_columns,
                  m, 1.0, l + columns, ld, panel, m, 0.0, below_update, static_cast<int>(below));
    }
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, panel_columns, m, 1.0, panel, m, 0.0,
                panel_gram, panel_columns);
    const int* below_rows = node.below_rows;
    for (std::size_t a = 0; a < active; ++a) {
      for (std::size_t d = 0; d < 3; ++d) {
        const std::size_t c = 3 * a + d;
        double* y = groups[work.active[a]].y + d * n;
        std::copy(panel + c * columns, panel + (c + 1) * columns, y + first);
        const double* u = below_update + c * below;
        for (std::size_t r = 0; r < below; ++r) y[std::size_t(below_rows[r])] -= u[r];
      }
    }
    // The panel's upper triangle into the groups' rows and columns (the
    // active groups ascend, so it lands on the upper triangle there too).
    for (std::size_t j = 0; j < std::size_t(panel_columns); ++j) {
      const std::size_t big_j = 3 * work.active[j / 3] + j % 3;
      for (std::size_t i = 0; i <= j; ++i) {
        const std::size_t big_i = 3 * work.active[i / 3] + i % 3;
        gram[big_i * width + big_j] += panel_gram[i + j * std::size_t(panel_columns)];
      }
    }
  }
  for (std::size_t i = 0; i < width; ++i) {
    for (std::size_t j = 0; j < i; ++j) gram[i * width + j] = gram[j * width + i];
  }
}

struct CholmodSolver::State {
  cholmod_common common{};
  cholmod_sparse view{};  // borrows the arrays of the caller's matrix
  cholmod_factor* factor = nullptr;
  SupernodalNumeric numeric_pass;  // refactorisations after the first
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
  // The supernodal elimination tree (sparse right-hand sides): the
  // supernode of each column, each supernode's parent (-1 at a root), the
  // inverse permutation, visit marks and a buffer for one supernode's
  // below-diagonal update. Built by analyze() for a supernodal analysis.
  std::vector<int> column_supernode;
  std::vector<int> parent;
  std::vector<int> position;  // position[dof] = its row in P b
  std::vector<std::uint32_t> marks;
  std::uint32_t mark = 0;
  std::vector<double> update;
  // solve_sparse: its right-hand side in the factor's ordering, the reach.
  std::vector<double> sparse_y;
  std::vector<int> sparse_reach;
  bool numeric = false;
  std::size_t rows = 0;

  // The background factorisation: its own CHOLMOD workspace, a second
  // factor with the same analysis, and a copy of the values it factorises
  // (the caller may assemble the next A meanwhile). `running` and `ok` are
  // guarded by `mutex`; the thread touches nothing else of the State but
  // these members while a job runs.
  struct Background {
    cholmod_common common{};
    cholmod_factor* factor = nullptr;
    SupernodalNumeric numeric_pass;
    cholmod_sparse view{};
    std::vector<double> values;
    std::thread thread;
    clockid_t cpu_clock{};
    std::mutex mutex;
    std::condition_variable wake;
    FillValues fill = nullptr;    // writes `values` on the thread, or null
    AfterFactor after = nullptr;  // solves on the new factor, or null
    void* fill_context = nullptr;
    // The sparse forward solves' marks and update buffer on this thread.
    std::vector<std::uint32_t> marks;
    std::uint32_t mark = 0;
    std::vector<double> update;
    // Thread CPU of the jobs so far by part (read while no job runs).
    BackgroundCpu cpu;
    bool job = false;      // a factorisation was asked for and not taken yet
    bool running = false;  // begun and not finished or cancelled
    bool ok = false;
    bool stop = false;
  };
  std::unique_ptr<Background> background;

  void run_background() {
    // Below the servo and haptic threads on a machine with few cores: on
    // Linux nice is per thread (PRIO_PROCESS with the thread's id). The
    // step waits for this thread only at the install step.
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kBackgroundNice);
    Background& b = *background;
    std::unique_lock lock(b.mutex);
    for (;;) {
      b.wake.wait(lock, [&] { return b.job || b.stop; });
      if (b.stop) return;
      const FillValues fill = b.fill;
      const AfterFactor after = b.after;
      void* const context = b.fill_context;
      lock.unlock();
      const std::int64_t t0 = thread_cpu_ns();
      if (fill != nullptr) fill(context, b.values);
      const std::int64_t t1 = thread_cpu_ns();
      const bool good = factorize_into(b.view, b.factor, b.common, b.numeric_pass);
      const std::int64_t t2 = thread_cpu_ns();
      if (good && after != nullptr) {
        NewFactor new_factor(this);
        after(context, new_factor);
      }
      const std::int64_t t3 = thread_cpu_ns();
      lock.lock();
      b.cpu.fill_ns += t1 - t0;
      b.cpu.factor_ns += t2 - t1;
      b.cpu.after_ns += t3 - t2;
      ++b.cpu.jobs;
      b.ok = good;
      b.job = false;
      b.wake.notify_all();
    }
  }

  // Waits for the running job, if any; true if it produced a factor.
  bool wait_background() {
    Background& b = *background;
    std::unique_lock lock(b.mutex);
    b.wake.wait(lock, [&] { return !b.job; });
    const bool good = b.running && b.ok;
    b.running = false;
    return good;
  }

  void stop_background() {
    if (!background) return;
    {
      std::lock_guard lock(background->mutex);
      background->stop = true;
    }
    background->wake.notify_all();
    if (background->thread.joinable()) background->thread.join();
    if (background->factor != nullptr)
      cholmod_free_factor(&background->factor, &background->common);
    cholmod_finish(&background->common);
    background.reset();
  }

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

  void build_tree() {
    column_supernode.clear();
    parent.clear();
    position.assign(rows, 0);
    const int* perm = static_cast<const int*>(factor->Perm);
    for (std::size_t k = 0; k < rows; ++k) position[static_cast<std::size_t>(perm[k])] = int(k);
    if (factor->is_super == 0) return;
    const auto nsuper = static_cast<int>(factor->nsuper);
    const int* super = static_cast<const int*>(factor->super);
    const int* pi = static_cast<const int*>(factor->pi);
    const int* srow = static_cast<const int*>(factor->s);
    column_supernode.assign(rows, 0);
    std::size_t widest = 0;
    for (int k = 0; k < nsuper; ++k) {
      for (int c = super[k]; c < super[k + 1]; ++c) column_supernode[std::size_t(c)] = k;
    }
    parent.assign(std::size_t(nsuper), -1);
    for (int k = 0; k < nsuper; ++k) {
      const int columns = super[k + 1] - super[k];
      const int rows_k = pi[k + 1] - pi[k];
      // The first row below the diagonal block lies in the parent supernode.
      if (rows_k > columns)
        parent[std::size_t(k)] = column_supernode[std::size_t(srow[pi[k] + columns])];
      widest = std::max(widest, std::size_t(rows_k - columns));
    }
    marks.assign(std::size_t(nsuper), 0);
    mark = 0;
    update.assign(3 * std::max<std::size_t>(widest, 1), 0.0);
    sparse_y.assign(rows, 0.0);
    sparse_reach.assign(std::size_t(nsuper), 0);
  }

  // The structure of `factor` for SupernodalNumeric, if supernodal LL'.
  void prepare_numeric_pass(SupernodalNumeric& pass) const {
    if (factor == nullptr || factor->is_super == 0 || factor->itype != CHOLMOD_INT) return;
    const auto nsuper = static_cast<std::size_t>(factor->nsuper);
    const auto* pi = static_cast<const int*>(factor->pi);
    const SupernodalPattern pattern{
        .super = {static_cast<const int*>(factor->super), nsuper + 1},
        .row_start = {pi, nsuper + 1},
        .rows = {static_cast<const int*>(factor->s), static_cast<std::size_t>(pi[nsuper])},
        .value_start = {static_cast<const int*>(factor->px), nsuper + 1},
        .perm = {static_cast<const int*>(factor->Perm), rows}};
    // An error leaves the pass unprepared: CHOLMOD factorises then.
    (void)pass.prepare(pattern, {static_cast<const int*>(view.p), rows + 1},
                       {static_cast<const int*>(view.i), view.nzmax});
  }

  ~State() {
    stop_background();
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
  // A new analysis: the background's factor belongs to the old one.
  const bool had_background = s.background != nullptr;
  s.stop_background();
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
  const bool analysed = s.factor != nullptr && s.common.status >= CHOLMOD_OK;
  if (analysed) {
    s.build_tree();
    s.prepare_numeric_pass(s.numeric_pass);
  }
  return analysed && (!had_background || enable_background());
}

bool CholmodSolver::enable_background() {
  State& s = *state_;
  if (s.background) return true;
  if (s.factor == nullptr) return false;
  auto b = std::make_unique<State::Background>();
  cholmod_start(&b->common);
  b->common.print = 0;
  b->common.supernodal = s.common.supernodal;
  // The same symbolic analysis (ordering, supernodes), no numeric values.
  cholmod_factor* symbolic = cholmod_copy_factor(s.factor, &s.common);
  if (symbolic == nullptr) {
    cholmod_finish(&b->common);
    return false;
  }
  b->factor = symbolic;
  b->values.assign(s.view.nzmax, 0.0);
  b->marks.assign(s.marks.size(), 0);
  b->update.assign(s.update.size(), 0.0);
  b->view = s.view;
  b->view.x = b->values.data();
  b->numeric_pass = s.numeric_pass;  // the same structure, its own workspace
  s.background = std::move(b);
  State* state = &s;
  s.background->thread = std::thread([state] { state->run_background(); });
  pthread_getcpuclockid(s.background->thread.native_handle(), &s.background->cpu_clock);
  return true;
}

bool CholmodSolver::begin_factorize(FillValues fill, void* context, AfterFactor after) {
  State& s = *state_;
  if (!s.background) return false;
  State::Background& b = *s.background;
  {
    std::lock_guard lock(b.mutex);
    if (b.running) return false;
    b.fill = fill;
    b.after = after;
    b.fill_context = context;
    if (fill == nullptr) std::memcpy(b.values.data(), s.view.x, sizeof(double) * b.values.size());
    b.running = true;
    b.job = true;
    b.ok = false;
  }
  b.wake.notify_all();
  return true;
}

bool CholmodSolver::finish_factorize() {
  State& s = *state_;
  if (!s.background || !s.wait_background()) return false;
  // The new factor takes the place of the old, which becomes the next
  // job's: both were allocated with the same (system) allocator.
  std::swap(s.factor, s.background->factor);
  s.numeric = true;
  ++s.factorisations;
  return true;
}

bool CholmodSolver::background_done() const {
  if (!state_->background) return true;
  State::Background& b = *state_->background;
  std::lock_guard lock(b.mutex);
  return !b.job;
}

void CholmodSolver::cancel_factorize() {
  if (state_->background) state_->wait_background();
}

BackgroundCpu CholmodSolver::background_parts() const {
  if (!state_->background) return {};
  State::Background& b = *state_->background;
  std::lock_guard lock(b.mutex);
  return b.cpu;
}

std::int64_t CholmodSolver::background_cpu_ns() const {
  if (!state_->background) return 0;
  timespec t{};
  if (clock_gettime(state_->background->cpu_clock, &t) != 0) return 0;
  return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
}

bool CholmodSolver::factorize() {
  State& s = *state_;
  if (s.factor == nullptr) return false;
  s.numeric = factorize_into(s.view, s.factor, s.common, s.numeric_pass);
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

bool CholmodSolver::sparse_forward_ready() const {
  const State& s = *state_;
  return s.numeric && s.factor != nullptr && s.factor->is_super != 0 && s.factor->is_ll != 0 &&
         !s.parent.empty();
}

std::size_t CholmodSolver::supernodes() const {
  return state_->parent.size();
}

int CholmodSolver::permuted(std::size_t dof) const {
  return state_->position[dof];
}

int CholmodSolver::supernode_first(int k) const {
  return static_cast<const int*>(state_->factor->super)[k];
}

int CholmodSolver::supernode_end(int k) const {
  return static_cast<const int*>(state_->factor->super)[k + 1];
}

const int* CholmodSolver::supernode_bounds() const {
  return static_cast<const int*>(state_->factor->super);
}

std::size_t CholmodSolver::reach(std::span<const std::uint32_t> dofs, std::span<int> out) {
  State& s = *state_;
  return tree_reach(s.column_supernode, s.parent, s.position, s.marks, s.mark, dofs, out);
}

void CholmodSolver::forward3_on_reach(std::span<const int> reach, std::span<double> y) {
  State& s = *state_;
  forward3_on_factor(*s.factor, s.rows, s.update, reach, y);
}

void CholmodSolver::solve_sparse(std::span<const std::uint32_t> dofs, std::span<const double> b,
                                 std::span<double> x) {
  State& s = *state_;
  const std::size_t count = reach(dofs, s.sparse_reach);
  std::fill(s.sparse_y.begin(), s.sparse_y.end(), 0.0);
  for (const std::uint32_t dof : dofs) s.sparse_y[std::size_t(s.position[dof])] = b[dof];
  forward_on_reach(*s.factor, s.update, {s.sparse_reach.data(), count}, s.sparse_y.data());
  backward_on_factor(*s.factor, s.update, s.sparse_y.data());
  for (std::size_t dof = 0; dof < s.rows; ++dof) x[dof] = s.sparse_y[std::size_t(s.position[dof])];
}

void CholmodSolver::forward_gram_on_reach(std::span<const HalfSolveColumns> groups,
                                          PanelWorkspace& work, std::span<double> gram) {
  State& s = *state_;
  forward_gram_on_factor(*s.factor, s.rows, groups, work, gram);
}

void CholmodSolver::reserve_panels(PanelWorkspace& work, std::size_t groups) const {
  const State& s = *state_;
  if (s.factor != nullptr && s.factor->is_super != 0) size_panels(*s.factor, groups, work);
}

std::size_t CholmodSolver::NewFactor::reach(std::span<const std::uint32_t> dofs,
                                            std::span<int> out) {
  State& s = *state_;
  State::Background& b = *s.background;
  return tree_reach(s.column_supernode, s.parent, s.position, b.marks, b.mark, dofs, out);
}

void CholmodSolver::NewFactor::forward3_on_reach(std::span<const int> reach, std::span<double> y) {
  State& s = *state_;
  forward3_on_factor(*s.background->factor, s.rows, s.background->update, reach, y);
}

void CholmodSolver::NewFactor::forward_gram_on_reach(std::span<const HalfSolveColumns> groups,
                                                     PanelWorkspace& work, std::span<double> gram) {
  State& s = *state_;
  forward_gram_on_factor(*s.background->factor, s.rows, groups, work, gram);
}

int CholmodSolver::NewFactor::permuted(std::size_t dof) const {
  return state_->position[dof];
}

int CholmodSolver::NewFactor::supernode_first(int k) const {
  return static_cast<const int*>(state_->background->factor->super)[k];
}

int CholmodSolver::NewFactor::supernode_end(int k) const {
  return static_cast<const int*>(state_->background->factor->super)[k + 1];
}

const int* CholmodSolver::NewFactor::supernode_bounds() const {
  return static_cast<const int*>(state_->background->factor->super);
}

bool CholmodSolver::NewFactor::sparse_forward_ready() const {
  const cholmod_factor* f = state_->background->factor;
  return f != nullptr && f->is_super != 0 && f->is_ll != 0 && !state_->parent.empty();
}

double CholmodSolver::factor_nonzeros() const {
  return state_->common.lnz;
}

bool CholmodSolver::supernodal() const {
  return state_->factor != nullptr && state_->factor->is_super != 0;
}

}  // namespace fahr::fem
