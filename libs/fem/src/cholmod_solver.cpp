// CHOLMOD through its C API (not Eigen's wrapper) so that solves can reuse
// their output and workspace buffers (cholmod_solve2) and allocate nothing.
#include "fahr/fem/cholmod_solver.h"

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

namespace fahr::fem {

namespace {
// The background factorisation's nice value (the logger's writer has 10).
constexpr int kBackgroundNice = 10;
}  // namespace

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

  // The background factorisation: its own CHOLMOD workspace, a second
  // factor with the same analysis, and a copy of the values it factorises
  // (the caller may assemble the next A meanwhile). `running` and `ok` are
  // guarded by `mutex`; the thread touches nothing else of the State but
  // these members while a job runs.
  struct Background {
    cholmod_common common{};
    cholmod_factor* factor = nullptr;
    cholmod_sparse view{};
    std::vector<double> values;
    std::thread thread;
    clockid_t cpu_clock{};
    std::mutex mutex;
    std::condition_variable wake;
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
      lock.unlock();
      const int ok = cholmod_factorize(&b.view, b.factor, &b.common);
      const bool good = ok != 0 && b.common.status == CHOLMOD_OK;
      lock.lock();
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
  b->view = s.view;
  b->view.x = b->values.data();
  s.background = std::move(b);
  State* state = &s;
  s.background->thread = std::thread([state] { state->run_background(); });
  pthread_getcpuclockid(s.background->thread.native_handle(), &s.background->cpu_clock);
  return true;
}

bool CholmodSolver::begin_factorize() {
  State& s = *state_;
  if (!s.background) return false;
  State::Background& b = *s.background;
  {
    std::lock_guard lock(b.mutex);
    if (b.running) return false;
    std::memcpy(b.values.data(), s.view.x, sizeof(double) * b.values.size());
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

void CholmodSolver::cancel_factorize() {
  if (state_->background) state_->wait_background();
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
