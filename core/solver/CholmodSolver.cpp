#include "solver/CholmodSolver.h"
#include "solver/ContactRelaxation.h"  // PatternRows
#include "solver/Memory.h"

#include <Eigen/Dense>

#include <cholmod.h>
#include <metis.h>

#include <dlfcn.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <set>
#include <stdexcept>

// BLAS and LAPACK in single precision (the system's, OpenBLAS on Debian: CHOLMOD's own).
extern "C" {
void ssyrk_(const char* uplo, const char* trans, const int* n, const int* k, const float* alpha,
            const float* a, const int* lda, const float* beta, float* c, const int* ldc);
void sgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const float* alpha, const float* a, const int* lda, const float* b, const int* ldb,
            const float* beta, float* c, const int* ldc);
void strsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
            const int* n, const float* alpha, const float* a, const int* lda, float* b,
            const int* ldb);
void spotrf_(const char* uplo, const int* n, float* a, const int* lda, int* info);
}

namespace tp {

namespace {

// OpenBLAS's thread count, when the BLAS behind CHOLMOD is OpenBLAS (looked up at run time: the
// reference BLAS has no such call). Triangular solves with one right-hand side are memory-bound
// and lose time to thread hand-offs; factorisations gain from threads, up to the count OpenBLAS
// started with (OPENBLAS_NUM_THREADS or OMP_NUM_THREADS, else every core). Asking for more than
// that (as this did before) woke OpenBLAS workers that then spin in sched_yield on the other
// core, a fifth of the time of a single-threaded run and the CPU of whatever runs beside it.
int maxBlasThreads() {
  using Get = int (*)();
  static const Get get = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  static const int n = get ? std::max(1, get()) : 1;
  return n;
}

std::atomic<int> blasThreadLimit{1 << 20};
std::mutex capMutex;
std::multiset<int> capsHeld;  // the BlasThreadCaps alive

// OpenBLAS's thread count is one for the whole process: solvers on several threads (the
// stiffness map's workers) share it under a lock, and their owner caps it (BlasThreadCap).
void setBlasThreads(int n) {
  using Fn = void (*)(int);
  static const Fn fn = reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  static std::mutex mutex;
  static int current = maxBlasThreads();  // captured before the first change
  n = std::clamp(n, 1, std::max(1, std::min(maxBlasThreads(), blasThreadLimit.load())));
  std::lock_guard lock(mutex);
  if (fn && n != current) {
    fn(n);
    current = n;
  }
}

}  // namespace

CholmodSolver::BlasThreadCap::BlasThreadCap(int threads) : threads_(std::max(1, threads)) {
  std::lock_guard lock(capMutex);
  capsHeld.insert(threads_);
  blasThreadLimit.store(*capsHeld.begin());
  setBlasThreads(1);
}

CholmodSolver::BlasThreadCap::~BlasThreadCap() {
  std::lock_guard lock(capMutex);
  capsHeld.erase(capsHeld.find(threads_));
  blasThreadLimit.store(capsHeld.empty() ? 1 << 20 : *capsHeld.begin());
  setBlasThreads(1);
}

int CholmodSolver::blasThreadCap() {
  std::lock_guard lock(capMutex);
  return capsHeld.empty() ? 0 : *capsHeld.begin();
}

struct CholmodSolver::Impl {
  cholmod_common common;
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  cholmod_dense* B = nullptr;
  cholmod_dense* X = nullptr;
  cholmod_dense* Y = nullptr;  // solve2 workspaces
  cholmod_dense* E = nullptr;
  bool factored = false;
  // The single-precision numeric factorisation on CHOLMOD's supernodal analysis (see
  // factorizeSingle): where each value of A goes in L, and its workspaces.
  bool singleReady = false;              // dest, diag, superOf built for the present analysis
  bool singleUnusable = false;           // the analysis is not the layout assumed: double only
  bool singleFactor = false;             // the held factor is factorF_ alone (L holds no values)
  double shift = 0;                      // of the held factorisation
  std::vector<std::int64_t> dest, diag;  // per value of A / per column: its place in L's values
  std::vector<int> superOf;              // per column: its supernode
  std::vector<int> head, next, lpos, map;
  std::vector<float> update;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;  // failures are reported through Status, not printed
  }
  ~Impl() {
    cholmod_free_dense(&B, &common);
    cholmod_free_dense(&X, &common);
    cholmod_free_dense(&Y, &common);
    cholmod_free_dense(&E, &common);
    cholmod_free_factor(&L, &common);
    cholmod_free_sparse(&A, &common);
    cholmod_finish(&common);
  }
};

CholmodSolver::CholmodSolver() {
  keepFreedMemory();
  impl_ = std::make_unique<Impl>();
}
CholmodSolver::~CholmodSolver() = default;

namespace {

// A fill-reducing ordering of the unknowns: METIS's nested dissection (METIS_NodeND) of the graph
// of their nodes, each node weighted by its number of unknowns, its unknowns then taken together
// in their order. With the vertices as nodes (a Koiter edge unknown a node of its own) the graph
// has a quarter of the arcs of the unknowns' graph that cholmod_analyze orders, and the ordering
// is about as good: on the default meristem's top, the analysis took 0.15–0.16 s against 0.26 s
// at level 3 and 0.46–0.47 s against 0.81–0.88 s at level 4, with 1.5 % and 4 % more nonzeros in
// the factor (none more at level 0, 10 % at level 2), BM_Analysis against BM_AnalysisOfUnknowns
// (bench/README.md, 2026-12-06). Without the weights the factors had 3–14 % more.
std::vector<int> nodeOrdering(const SparsePattern& pattern, std::span<const int> node) {
  const int n = pattern.n;
  const int nodes = *std::max_element(node.begin(), node.end()) + 1;
  std::vector<int> first(nodes + 1, 0), member(n);  // each node's unknowns, ascending
  for (int i = 0; i < n; ++i) ++first[node[i] + 1];
  for (int k = 0; k < nodes; ++k) first[k + 1] += first[k];
  {
    std::vector<int> at(first.begin(), first.end() - 1);
    for (int i = 0; i < n; ++i) member[at[node[i]]++] = i;
  }
  // The pattern's rows, to see each unknown's couplings on both sides of the diagonal.
  PatternRows rows;
  rows.build(pattern);
  // The node graph in METIS's layout: each node's neighbours once, no loops.
  std::vector<idx_t> xadj(nodes + 1, 0), adjncy, weight(nodes);
  adjncy.reserve(pattern.rowIdx.size() / 2);
  std::vector<int> mark(nodes, -1);
  for (int c = 0; c < nodes; ++c) {
    mark[c] = c;
    auto add = [&](int unknown) {
      const int b = node[unknown];
      if (mark[b] != c) {
        mark[b] = c;
        adjncy.push_back(b);
      }
    };
    for (int k = first[c]; k < first[c + 1]; ++k) {
      const int j = member[k];
      for (int q = pattern.colPtr[j]; q < pattern.colPtr[j + 1]; ++q) add(pattern.rowIdx[q]);
      for (int q = rows.start[j]; q < rows.start[j + 1]; ++q) add(rows.col[q]);
    }
    xadj[c + 1] = static_cast<idx_t>(adjncy.size());
    weight[c] = std::max(first[c + 1] - first[c], 1);  // METIS wants positive weights
  }
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  idx_t count = nodes;
  std::vector<idx_t> perm(nodes), iperm(nodes);
  if (adjncy.empty()) adjncy.push_back(0);  // a valid pointer for METIS when nothing couples
  const int status = METIS_NodeND(&count, xadj.data(), adjncy.data(), weight.data(), options,
                                  perm.data(), iperm.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS: the ordering of the vertices failed (status " +
                             std::to_string(status) + ")");
  std::vector<int> order;
  order.reserve(n);
  for (idx_t c : perm)
    for (int k = first[c]; k < first[c + 1]; ++k) order.push_back(member[k]);
  return order;
}

}  // namespace

bool CholmodSolver::analyzed() const { return impl_->L != nullptr; }

void CholmodSolver::analyze(const SparsePattern& pattern, std::span<const int> node) {
  Impl& m = *impl_;
  cholmod_free_factor(&m.L, &m.common);
  cholmod_free_sparse(&m.A, &m.common);
  cholmod_free_dense(&m.B, &m.common);
  m.factored = false;
  m.singleReady = m.singleFactor = m.singleUnusable = false;
  const size_t n = pattern.n;
  m.A = cholmod_allocate_sparse(n, n, pattern.nnz(), 1, 1, 1, CHOLMOD_REAL, &m.common);
  if (!m.A) throw std::runtime_error("CHOLMOD: cannot allocate the matrix");
  // memcpy from or to a null pointer is undefined even for 0 bytes (an empty pattern: every
  // vertex clamped), so only non-empty arrays are copied.
  std::memcpy(m.A->p, pattern.colPtr.data(), sizeof(int) * (n + 1));
  if (pattern.nnz() > 0) {
    std::memcpy(m.A->i, pattern.rowIdx.data(), sizeof(int) * pattern.nnz());
    std::memset(m.A->x, 0, sizeof(double) * pattern.nnz());
  }
  {
    // One analysis at a time in the process: the orderings use METIS, and Debian's METIS
    // draws its random numbers from libc's rand(), one generator for the process, seeded with
    // srand() at every call. Two analyses at once (a stiffness map's workers) drew from each
    // other's sequence, so the same site got another ordering, hence other last bits, from run
    // to run and with the number of workers. The wait is short: analyses are about a tenth of
    // a map site's time (a seventh before they ordered the vertices' graph, bench/README.md).
    static std::mutex orderingMutex;
    std::lock_guard lock(orderingMutex);
    if (!node.empty() && n > 0) {
      if (node.size() != n || *std::min_element(node.begin(), node.end()) < 0)
        throw std::invalid_argument("CholmodSolver::analyze: a node for every unknown");
      const std::vector<int> order = nodeOrdering(pattern, node);
      m.common.nmethods = 1;
      m.common.method[0].ordering = CHOLMOD_GIVEN;
      m.L = cholmod_analyze_p(m.A, const_cast<int*>(order.data()), nullptr, 0, &m.common);
    } else {
      m.common.nmethods = 0;  // CHOLMOD's choice: AMD, and METIS when AMD fills much
      m.L = cholmod_analyze(m.A, &m.common);
    }
  }
  if (!m.L || m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: symbolic analysis failed (status " +
                             std::to_string(m.common.status) + ")");
  m.B = cholmod_zeros(n, 1, CHOLMOD_REAL, &m.common);
  scheduleValid_ = false;
}

CholmodSolver::Status CholmodSolver::factorize(std::span<const double> values, double shift) {
  Impl& m = *impl_;
  if (!m.L) throw std::logic_error("CholmodSolver::factorize before analyze");
  if (values.size() != m.A->nzmax) throw std::invalid_argument("CholmodSolver: value count mismatch");
  m.factored = false;
  for (double v : values)
    if (!std::isfinite(v)) {
      message_ = "tangent matrix has non-finite entries";
      return Status::NonFinite;
    }
  if (!values.empty()) std::memcpy(m.A->x, values.data(), sizeof(double) * values.size());
  setBlasThreads(maxBlasThreads());
  m.shift = shift;
  m.singleFactor = false;
  if (precision_ == Precision::Single && factorizeSingle(shift)) {
    m.singleFactor = true;
    m.factored = true;
    factorFValid_ = true;
    message_.clear();
    return Status::Ok;
  }
  factorFValid_ = false;  // a failed single-precision attempt leaves nothing to solve with
  double beta[2] = {shift, 0.0};
  // Debian's CHOLMOD assembles each supernode in an OpenMP loop of a team size fixed when it was
  // built (CHOLMOD_OMP_NUM_THREADS, 4), whatever OMP_NUM_THREADS says: on two cores that is four
  // threads forking and joining per supernode, waking each other through the kernel. With
  // dynamic adjustment (this thread's setting only, restored after) the runtime gives the team
  // no more threads than there are idle cores. Measured on the 2-core VM, `tissueprobe-cli indent
  // --depth 0.5 --steps 5 --refine 3 --probe-radius 3`: 41.3 -> 36.6 s; with OMP_NUM_THREADS=1
  // and OPENBLAS_NUM_THREADS=1 (CI's slow tests) 54.6 -> 41.2 s, a quarter of the time.
  // Those loops only clear and scatter values (memory-bound; the flops are OpenBLAS's, threaded
  // on their own), and libgomp reads the load average and the affinity mask for every dynamic
  // team: with this thread's team size at one as well, every region of the factorisation is
  // one thread run directly (solver/OpenMpRegions.h). BM_Factorization/3 and /4 (two threads,
  // medians of 5, builds alternated): 166, 155 ms and 495, 473 ms with dynamic teams; 148,
  // 115 ms and 448, 367 ms with one thread.
  const int dynamic = omp_get_dynamic(), threads = omp_get_max_threads();
  omp_set_dynamic(1);
  omp_set_num_threads(1);
  const int ok = cholmod_factorize_p(m.A, beta, nullptr, 0, m.L, &m.common);
  omp_set_num_threads(threads);
  omp_set_dynamic(dynamic);
  if (m.common.status == CHOLMOD_NOT_POSDEF || (ok && m.L->minor < m.L->n)) {
    message_ = "tangent matrix not positive definite (column " + std::to_string(m.L->minor) + ")";
    return Status::NotPositiveDefinite;
  }
  if (!ok || m.common.status < CHOLMOD_OK) {
    message_ = "CHOLMOD factorisation failed (status " + std::to_string(m.common.status) + ")";
    return Status::Failed;
  }
  m.factored = true;
  factorFValid_ = false;
  message_.clear();
  return Status::Ok;
}

void CholmodSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& m = *impl_;
  if (!m.factored) throw std::logic_error("CholmodSolver::solve without a factorisation");
  const size_t n = m.L->n;
  if (static_cast<size_t>(b.size()) != n) throw std::invalid_argument("CholmodSolver: rhs size");
  if (m.singleFactor) {
    // Iterative refinement: each correction from the single-precision factor, each residual
    // in double with A itself, until the residual stops falling (Wilkinson; Higham, "Accuracy
    // and Stability of Numerical Algorithms", 2002, §12.1).
    const int* Ap = static_cast<const int*>(m.A->p);
    const int* Ai = static_cast<const int*>(m.A->i);
    const double* Ax = static_cast<const double*>(m.A->x);
    const auto residual = [&](const Eigen::VectorXd& y, Eigen::VectorXd& r) {
      r = b - m.shift * y;
      for (size_t j = 0; j < n; ++j)
        for (int k = Ap[j]; k < Ap[j + 1]; ++k) {
          const int i = Ai[k];
          r[i] -= Ax[k] * y[j];
          if (static_cast<size_t>(i) != j) r[j] -= Ax[k] * y[i];
        }
    };
    x.setZero(static_cast<Eigen::Index>(n));
    Eigen::VectorXd r = b, z;
    double last = r.norm();
    const double target = 1e-14 * last;
    for (int it = 0; it < 10 && last > target; ++it) {
      solveSinglePrecision(r, z, 1);
      x += z;
      residual(x, r);
      const double now = r.norm();
      if (!(now < 0.5 * last)) break;
      last = now;
    }
    return;
  }
  if (n > 0) std::memcpy(m.B->x, b.data(), sizeof(double) * n);
  setBlasThreads(1);
  if (!cholmod_solve2(CHOLMOD_A, m.L, m.B, nullptr, &m.X, nullptr, &m.Y, &m.E, &m.common))
    throw std::runtime_error("CHOLMOD: solve failed");
  x.resize(n);
  if (n > 0) std::memcpy(x.data(), m.X->x, sizeof(double) * n);
}

namespace {

// The passes of SupernodalFactor are compiled twice with GCC on x86-64, for the baseline and for
// AVX2 with FMA (x86-64-v3), and the loader picks the one the processor runs (function multi-
// versioning). One solve at levels 3 and 4 of the default meristem, alternated in one process
// (2026-12-06): 0.92 × the time of Eigen's kernels per supernode with the baseline build of these
// loops, 0.71–0.75 × with the x86-64-v3 one.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define TP_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define TP_SIMD_CLONES
#endif

// One supernode's part of L y = b (forward) and of Lᵀ z = y (backward), in single precision.
// Supernode s holds columns super[s]..super[s+1)-1 as a dense column-major block whose rows are
// rows[pi[s]..pi[s+1]), the first of which are those columns themselves; its off-diagonal rows
// belong to its ancestors in the elimination tree.
struct SupernodalFactor {
  const float* x;
  const int *super, *pi, *px, *rows;

  // Each pass works in z = [y_k ; y_rows], the supernode's entries of y gathered (k its columns
  // k1 … k1 + nc − 1, rows its nr − nc rows below). Columns go four at a time: their small
  // triangle, then one loop over the rows below it that reads each of the four columns once and
  // z once for all four (an axpy of four columns forward, four dot products backward): simple
  // loops the compiler vectorises, reading the block once.
  TP_SIMD_CLONES void forward(int s, float* y, Eigen::VectorXf& t) const {
    const int k1 = super[s], nc = super[s + 1] - k1, nr = pi[s + 1] - pi[s];
    t.resize(nr);
    float* z = t.data();
    for (int i = 0; i < nc; ++i) z[i] = y[k1 + i];
    for (int i = nc; i < nr; ++i) z[i] = 0.0f;
    for (int j = 0; j < nc; j += 4) {
      const int w = std::min(4, nc - j);
      const float* c[4];
      for (int a = 0; a < w; ++a) c[a] = x + px[s] + static_cast<std::ptrdiff_t>(j + a) * nr;
      for (int a = 0; a < w; ++a) {  // the triangle of rows j … j + w − 1
        z[j + a] /= c[a][j + a];
        for (int b = a + 1; b < w; ++b) z[j + b] -= c[a][j + b] * z[j + a];
      }
      if (w == 4) {
        const float* c0 = c[0];
        const float* c1 = c[1];
        const float* c2 = c[2];
        const float* c3 = c[3];
        const float z0 = z[j], z1 = z[j + 1], z2 = z[j + 2], z3 = z[j + 3];
#pragma omp simd
        for (int i = j + 4; i < nr; ++i) z[i] -= c0[i] * z0 + c1[i] * z1 + c2[i] * z2 + c3[i] * z3;
      } else {
        for (int a = 0; a < w; ++a) {
          const float* ca = c[a];
          const float za = z[j + a];
#pragma omp simd
          for (int i = j + w; i < nr; ++i) z[i] -= ca[i] * za;
        }
      }
    }
    for (int i = 0; i < nc; ++i) y[k1 + i] = z[i];
    const int* r = rows + pi[s];
    for (int i = nc; i < nr; ++i) y[r[i]] += z[i];
  }
  TP_SIMD_CLONES void backward(int s, float* y, Eigen::VectorXf& t) const {
    const int k1 = super[s], nc = super[s + 1] - k1, nr = pi[s + 1] - pi[s];
    t.resize(nr);
    float* z = t.data();
    const int* r = rows + pi[s];
    for (int i = 0; i < nc; ++i) z[i] = y[k1 + i];
    for (int i = nc; i < nr; ++i) z[i] = y[r[i]];
    for (int end = nc; end > 0;) {
      const int w = std::min(4, end), j = end - w;  // columns j … end − 1
      const float* c[4];
      float d[4] = {0.0f, 0.0f, 0.0f, 0.0f};
      for (int a = 0; a < w; ++a) c[a] = x + px[s] + static_cast<std::ptrdiff_t>(j + a) * nr;
      if (w == 4) {  // the rows below the group's triangle, all final
        const float* c0 = c[0];
        const float* c1 = c[1];
        const float* c2 = c[2];
        const float* c3 = c[3];
        float d0 = 0.0f, d1 = 0.0f, d2 = 0.0f, d3 = 0.0f;
#pragma omp simd reduction(+ : d0, d1, d2, d3)
        for (int i = end; i < nr; ++i) {
          d0 += c0[i] * z[i];
          d1 += c1[i] * z[i];
          d2 += c2[i] * z[i];
          d3 += c3[i] * z[i];
        }
        d[0] = d0, d[1] = d1, d[2] = d2, d[3] = d3;
      } else {
        for (int a = 0; a < w; ++a) {
          const float* ca = c[a];
          float da = 0.0f;
#pragma omp simd reduction(+ : da)
          for (int i = end; i < nr; ++i) da += ca[i] * z[i];
          d[a] = da;
        }
      }
      for (int a = w - 1; a >= 0; --a) {  // the triangle, bottom up
        float sum = d[a];
        for (int b = a + 1; b < w; ++b) sum += c[a][j + b] * z[j + b];
        z[j + a] = (z[j + a] - sum) / c[a][j + a];
      }
      end = j;
    }
    for (int i = 0; i < nc; ++i) y[k1 + i] = z[i];
  }
};

}  // namespace

const CholmodSolver::SolveSchedule& CholmodSolver::solveSchedule() {
  if (scheduleValid_) return schedule_;
  const cholmod_factor* L = impl_->L;
  if (!L) throw std::logic_error("CholmodSolver::solveSchedule before analyze");
  SolveSchedule sc;
  const int nsuper = L->is_super ? static_cast<int>(L->nsuper) : 0;
  const int* super = static_cast<const int*>(L->super);
  const int* pi = static_cast<const int*>(L->pi);
  const int* rows = static_cast<const int*>(L->s);
  sc.owner.assign(nsuper, 2);
  // The supernodal elimination tree: a supernode's parent holds its first off-diagonal row.
  // Work of a supernode ~ its block's size (each entry is read once per triangular solve).
  std::vector<int> colSuper(L->n, -1), parent(nsuper, -1);
  std::vector<double> work(nsuper), subtree(nsuper);
  std::vector<std::vector<int>> children(nsuper);
  for (int s = 0; s < nsuper; ++s)
    for (int k = super[s]; k < super[s + 1]; ++k) colSuper[k] = s;
  double total = 0;
  for (int s = 0; s < nsuper; ++s) {
    const int nc = super[s + 1] - super[s], nr = pi[s + 1] - pi[s];
    work[s] = static_cast<double>(nr) * nc;
    total += work[s];
    if (nr > nc) parent[s] = colSuper[rows[pi[s] + nc]];
  }
  std::vector<int> frontier;
  for (int s = 0; s < nsuper; ++s) {  // children come before their parent in CHOLMOD's order
    subtree[s] += work[s];
    if (parent[s] >= 0) {
      subtree[parent[s]] += subtree[s];
      children[parent[s]].push_back(s);
    } else {
      frontier.push_back(s);
    }
  }
  // Split greedily: assign the frontier's subtrees to two threads (largest first, to the lighter
  // one); while that is unbalanced, move the largest subtree's root to the serial top and put its
  // children in the frontier. Keep the split with the smallest estimated time.
  double best = total, topWork = 0;
  std::vector<int> bestFrontier, bestBins;
  for (int round = 0; round < 256 && !frontier.empty(); ++round) {
    std::sort(frontier.begin(), frontier.end(),
              [&](int a, int b) { return subtree[a] > subtree[b]; });
    double bin[2] = {0, 0};
    std::vector<int> bins(frontier.size());
    for (size_t i = 0; i < frontier.size(); ++i) {
      bins[i] = bin[0] <= bin[1] ? 0 : 1;
      bin[bins[i]] += subtree[frontier[i]];
    }
    const double estimate = topWork + std::max(bin[0], bin[1]);
    if (bin[0] > 0 && bin[1] > 0 && estimate < best) {
      best = estimate;
      bestFrontier = frontier;
      bestBins = bins;
    }
    const int h = frontier.front();
    if (children[h].empty() || std::max(bin[0], bin[1]) <= 0.52 * (bin[0] + bin[1])) break;
    frontier.erase(frontier.begin());
    topWork += work[h];
    frontier.insert(frontier.end(), children[h].begin(), children[h].end());
  }
  for (size_t i = 0; i < bestFrontier.size(); ++i) {
    std::vector<int> stack{bestFrontier[i]};
    while (!stack.empty()) {
      const int s = stack.back();
      stack.pop_back();
      sc.owner[s] = static_cast<std::uint8_t>(bestBins[i]);
      stack.insert(stack.end(), children[s].begin(), children[s].end());
    }
  }
  for (int s = 0; s < nsuper; ++s) {
    sc.supers[sc.owner[s]].push_back(s);
    if (sc.owner[s] == 0) continue;
    auto& list = sc.owner[s] == 1 ? sc.rows1 : sc.rowsTop;
    for (int k = super[s]; k < super[s + 1]; ++k) list.push_back(k);
  }
  sc.parallelFraction = total > 0 ? best / total : 1;
  schedule_ = std::move(sc);
  scheduleValid_ = true;
  return schedule_;
}

void CholmodSolver::solveSinglePrecision(const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                         int threads) {
  Impl& m = *impl_;
  if (!m.factored) throw std::logic_error("CholmodSolver::solve without a factorisation");
  const cholmod_factor* L = m.L;
  if (!m.singleFactor && (!L->is_super || !L->is_ll)) {  // not the supernodal LLᵀ of this code
    solve(b, x);
    return;
  }
  if (!factorFValid_) {
    const double* lx = static_cast<const double*>(L->x);
    factorF_.assign(lx, lx + L->xsize);
    factorFValid_ = true;
  }
  const SupernodalFactor F{factorF_.data(), static_cast<const int*>(L->super),
                           static_cast<const int*>(L->pi), static_cast<const int*>(L->px),
                           static_cast<const int*>(L->s)};
  const int n = static_cast<int>(L->n);
  const int* perm = static_cast<const int*>(L->Perm);
  // P A Pᵀ = L Lᵀ: y = P b, then L y' = y, then Lᵀ z = y', x = Pᵀ z.
  Eigen::VectorXf y(n), t;
  for (int k = 0; k < n; ++k) y[k] = static_cast<float>(b[perm[k]]);
  const int nsuper = static_cast<int>(L->nsuper);
  if (threads <= 0) threads = omp_get_max_threads();
  if (threads < 2 || omp_in_parallel() || solveSchedule().parallelFraction > 0.8) {
    for (int s = 0; s < nsuper; ++s) F.forward(s, y.data(), t);
    for (int s = nsuper - 1; s >= 0; --s) F.backward(s, y.data(), t);
  } else {
    // Forward: the two threads' subtrees at once — thread 0 in y, thread 1 in its own copy y1
    // whose top rows start at 0 and collect thread 1's updates to them — then the top serially.
    // Backward: the top first, then the subtrees at once (each reads the top and its own rows).
    const SolveSchedule& sc = schedule_;
    Eigen::VectorXf y1 = y;
    for (int r : sc.rowsTop) y1[r] = 0;
#pragma omp parallel num_threads(2)
    {
      Eigen::VectorXf tt;
      if (omp_get_thread_num() == 0)
        for (int s : sc.supers[0]) F.forward(s, y.data(), tt);
      else
        for (int s : sc.supers[1]) F.forward(s, y1.data(), tt);
    }
    for (int r : sc.rows1) y[r] = y1[r];
    for (int r : sc.rowsTop) y[r] += y1[r];
    for (int s : sc.supers[2]) F.forward(s, y.data(), t);
    for (auto it = sc.supers[2].rbegin(); it != sc.supers[2].rend(); ++it)
      F.backward(*it, y.data(), t);
#pragma omp parallel num_threads(2)
    {
      Eigen::VectorXf tt;
      const auto& mine = sc.supers[omp_get_thread_num() == 0 ? 0 : 1];
      for (auto it = mine.rbegin(); it != mine.rend(); ++it) F.backward(*it, y.data(), tt);
    }
  }
  x.resize(n);
  for (int k = 0; k < n; ++k) x[perm[k]] = y[k];
}

bool CholmodSolver::factored() const { return impl_->factored; }
bool CholmodSolver::singlePrecisionFactor() const {
  return impl_->factored && impl_->singleFactor;
}

// The numeric factorisation P (A + shift I) Pᵀ = L Lᵀ in single precision, on CHOLMOD's
// supernodal analysis (the same supernodes, rows and value layout as its own factor, so that
// the preconditioner's solves read it unchanged): left-looking, each supernode assembled from
// A's values and the updates of the supernodes below it in the elimination tree (a syrk and a
// gemm each), then its diagonal block factorised (potrf) and the rows below it solved (trsm) —
// the supernodal method of Ng & Peyton (SIAM J. Sci. Comput. 14, 1993) that CHOLMOD runs in
// double. False when the analysis is not supernodal (or not laid out as assumed: then never
// tried again for it) or a diagonal block is not positive definite in single precision;
// factorize() then asks CHOLMOD in double.
bool CholmodSolver::factorizeSingle(double shift) {
  Impl& m = *impl_;
  const cholmod_factor* L = m.L;
  if (!L->is_super || m.singleUnusable) return false;
  const int n = static_cast<int>(L->n), nsuper = static_cast<int>(L->nsuper);
  const int* super = static_cast<const int*>(L->super);
  const int* pi = static_cast<const int*>(L->pi);
  const int* px = static_cast<const int*>(L->px);
  const int* rows = static_cast<const int*>(L->s);
  const int* Ap = static_cast<const int*>(m.A->p);
  const int* Ai = static_cast<const int*>(m.A->i);
  const double* Ax = static_cast<const double*>(m.A->x);
  if (!m.singleReady) {
    // Where each value of A lands in L's values: A's (i, j) is L's (max, min) of the permuted
    // indices, in the supernode of that column, at that row's place in the supernode's rows.
    const int* perm = static_cast<const int*>(L->Perm);
    std::vector<int> inv(n);
    for (int k = 0; k < n; ++k) inv[perm[k]] = k;
    m.superOf.assign(n, 0);
    for (int s = 0; s < nsuper; ++s)
      for (int c = super[s]; c < super[s + 1]; ++c) m.superOf[c] = s;
    const int nnz = Ap[n];
    std::vector<int> start(n + 1, 0), byColumn(nnz), columnOf(nnz);
    for (int j = 0; j < n; ++j)
      for (int k = Ap[j]; k < Ap[j + 1]; ++k) columnOf[k] = j;
    for (int j = 0; j < n; ++j)
      for (int k = Ap[j]; k < Ap[j + 1]; ++k) ++start[std::min(inv[Ai[k]], inv[j]) + 1];
    for (int c = 0; c < n; ++c) start[c + 1] += start[c];
    {
      std::vector<int> at(start.begin(), start.end() - 1);
      for (int j = 0; j < n; ++j)
        for (int k = Ap[j]; k < Ap[j + 1]; ++k) byColumn[at[std::min(inv[Ai[k]], inv[j])]++] = k;
    }
    m.dest.assign(nnz, -1);
    m.diag.assign(n, 0);
    m.map.assign(n, -1);
    for (int s = 0; s < nsuper; ++s) {
      const int k1 = super[s], nsrow = pi[s + 1] - pi[s], nscol = super[s + 1] - k1;
      for (int i = 0; i < nsrow; ++i) {
        const int r = rows[pi[s] + i];
        // The rows below the diagonal block ascending, as the updates below assume.
        if ((i < nscol && r != k1 + i) || (i > nscol && r <= rows[pi[s] + i - 1]))
          return !(m.singleUnusable = true);
        m.map[r] = i;
      }
      for (int c = k1; c < k1 + nscol; ++c) {
        m.diag[c] = px[s] + static_cast<std::int64_t>(c - k1) * nsrow + (c - k1);
        for (int q = start[c]; q < start[c + 1]; ++q) {
          const int k = byColumn[q];
          const int r = std::max(inv[Ai[k]], inv[columnOf[k]]);
          if (r < k1 || m.map[r] < 0 || rows[pi[s] + m.map[r]] != r)
            return !(m.singleUnusable = true);
          m.dest[k] = px[s] + static_cast<std::int64_t>(c - k1) * nsrow + m.map[r];
        }
      }
    }
    m.head.assign(nsuper, -1);
    m.next.assign(nsuper, -1);
    m.lpos.assign(nsuper, 0);
    m.singleReady = true;
  }
  std::vector<float>& x = factorF_;
  x.assign(L->xsize, 0.0f);
  for (size_t k = 0; k < m.dest.size(); ++k) x[m.dest[k]] += static_cast<float>(Ax[k]);
  if (shift != 0)
    for (int c = 0; c < n; ++c) x[m.diag[c]] += static_cast<float>(shift);
  std::fill(m.head.begin(), m.head.end(), -1);
  const float one = 1.0f, zero = 0.0f;
  for (int s = 0; s < nsuper; ++s) {
    const int k1 = super[s], k2 = super[s + 1], nscol = k2 - k1;
    const int nsrow = pi[s + 1] - pi[s];
    float* Ls = x.data() + px[s];
    for (int i = 0; i < nsrow; ++i) m.map[rows[pi[s] + i]] = i;
    // The updates of the supernodes whose next rows fall in this one's columns.
    for (int d = m.head[s]; d >= 0;) {
      const int dnext = m.next[d];
      const int ndrow = pi[d + 1] - pi[d], ndcol = super[d + 1] - super[d];
      const int p = m.lpos[d];
      const int* drows = rows + pi[d];
      int ndrow1 = 0;
      while (p + ndrow1 < ndrow && drows[p + ndrow1] < k2) ++ndrow1;
      const int ndrow2 = ndrow - p;
      const float* Ld = x.data() + px[d];
      m.update.resize(static_cast<size_t>(ndrow2) * ndrow1);
      float* C = m.update.data();
      // C = L_d[p:, :] L_d[p : p + ndrow1, :]ᵀ, its top ndrow1 × ndrow1 lower triangle by syrk.
      ssyrk_("L", "N", &ndrow1, &ndcol, &one, Ld + p, &ndrow, &zero, C, &ndrow2);
      const int below = ndrow2 - ndrow1;
      if (below > 0)
        sgemm_("N", "T", &below, &ndrow1, &ndcol, &one, Ld + p + ndrow1, &ndrow, Ld + p, &ndrow,
               &zero, C + ndrow1, &ndrow2);
      for (int jj = 0; jj < ndrow1; ++jj) {
        float* column = Ls + static_cast<std::ptrdiff_t>(drows[p + jj] - k1) * nsrow;
        const float* c = C + static_cast<std::ptrdiff_t>(jj) * ndrow2;
        for (int ii = jj; ii < ndrow2; ++ii) column[m.map[drows[p + ii]]] -= c[ii];
      }
      m.lpos[d] = p + ndrow1;
      if (m.lpos[d] < ndrow) {
        const int t = m.superOf[drows[m.lpos[d]]];
        m.next[d] = m.head[t];
        m.head[t] = d;
      }
      d = dnext;
    }
    int info = 0;
    spotrf_("L", &nscol, Ls, &nsrow, &info);
    if (info != 0) {
      message_ = "tangent matrix not positive definite in single precision (column " +
                 std::to_string(k1 + info - 1) + ")";
      return false;
    }
    const int below = nsrow - nscol;
    if (below > 0) {
      strsm_("R", "L", "T", "N", &below, &nscol, &one, Ls, &nsrow, Ls + nscol, &nsrow);
      m.lpos[s] = nscol;
      const int t = m.superOf[rows[pi[s] + nscol]];
      m.next[s] = m.head[t];
      m.head[t] = s;
    }
  }
  return true;
}

double CholmodSolver::factorFlops() const {
  const Impl& m = *impl_;
  return m.L ? m.common.fl : 0.0;
}

double CholmodSolver::factorNonzeros() const {
  const Impl& m = *impl_;
  return m.L ? m.common.lnz : 0.0;
}

}  // namespace tp
