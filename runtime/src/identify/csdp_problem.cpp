#include "csdp_problem.hpp"

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <new>
#include <stdexcept>

#include <fmt/format.h>

extern "C" {
#include <csdp/declarations.h>
}

namespace symoro::identify::detail {

namespace {

// CSDP's op_o() keeps its work array in a function-static pointer (libsdp's only writable
// global, `work.0`), so two solves at once would share it: one lock for every CSDP call.
std::mutex& csdp_mutex() {
  static std::mutex m;
  return m;
}

template <class T>
T* allocate(std::size_t count) {
  // CSDP frees what it is given with free(): allocate with malloc.
  void* p = std::calloc(count == 0 ? 1 : count, sizeof(T));
  if (!p) throw std::bad_alloc();
  return static_cast<T*>(p);
}

// Every CSDP-side allocation of one solve, released in the destructor whatever happens.
struct CsdpWorkspace {
  int n = 0, k = 0;
  blockmatrix C{0, nullptr};
  double* a = nullptr;
  constraintmatrix* constraints = nullptr;
  sparseblock** byblocks = nullptr;
  constraintmatrix fill{nullptr};
  bool have_fill = false;
  blockmatrix X{0, nullptr}, Z{0, nullptr};
  double* y = nullptr;
  blockmatrix work1{0, nullptr}, work2{0, nullptr}, work3{0, nullptr};
  blockmatrix Zi{0, nullptr}, dZ{0, nullptr}, dX{0, nullptr};
  blockmatrix bestx{0, nullptr}, bestz{0, nullptr}, cholxinv{0, nullptr}, cholzinv{0, nullptr};
  std::vector<double*> vectors;  // workvec1..8, diagO, besty, rhs, dy, dy1, Fp, O

  double* vector(std::size_t size) {
    vectors.push_back(allocate<double>(size));
    return vectors.back();
  }

  static void free_list(sparseblock* p) {
    while (p) {
      sparseblock* next = p->next;
      std::free(p->entries);
      std::free(p->iindices);
      std::free(p->jindices);
      std::free(p);
      p = next;
    }
  }

  ~CsdpWorkspace() {
    for (blockmatrix* m : {&C, &X, &Z, &work1, &work2, &work3, &Zi, &dZ, &dX})
      if (m->blocks) free_mat(*m);
    for (blockmatrix* m : {&bestx, &bestz, &cholxinv, &cholzinv})
      if (m->blocks) free_mat_packed(*m);
    if (constraints) {
      for (int i = 1; i <= k; ++i) free_list(constraints[i].blocks);
      std::free(constraints);
    }
    if (have_fill) free_list(fill.blocks);
    std::free(byblocks);
    std::free(a);
    std::free(y);
    for (double* v : vectors) std::free(v);
  }
};

// C = -F_k0 per block, exactly symmetric (CSDP checks C(i,j) == C(j,i) bitwise).
void set_constant(CsdpWorkspace& w, const std::vector<Eigen::MatrixXd>& constant) {
  const int nb = static_cast<int>(constant.size());
  for (const auto& c : constant) w.n += static_cast<int>(c.rows());
  w.C.nblocks = nb;
  w.C.blocks = allocate<blockrec>(nb + 1);
  for (int b = 0; b < nb; ++b) {
    const Eigen::MatrixXd& F = constant[b];
    const int s = static_cast<int>(F.rows());
    blockrec& r = w.C.blocks[b + 1];
    r.blockcategory = MATRIX;
    r.blocksize = s;
    r.data.mat = allocate<double>(static_cast<std::size_t>(s) * s);
    for (int i = 0; i < s; ++i)
      for (int j = i; j < s; ++j) {
        const double v = i == j ? -F(i, i) : -0.5 * (F(i, j) + F(j, i));
        r.data.mat[ijtok(i + 1, j + 1, s)] = v;
        r.data.mat[ijtok(j + 1, i + 1, s)] = v;
      }
  }
}

// The constraint matrices: per variable a list of its nonzero blocks, ascending.
// coefficient[variable][block]: the entries {i, j, value} of F_ki's upper triangle.
template <class Coefficients>
void set_constraints(CsdpWorkspace& w, const Coefficients& coefficient) {
  const int k = w.k, nb = w.C.nblocks;
  w.constraints = allocate<constraintmatrix>(k + 1);
  for (int v = 0; v < k; ++v) {
    sparseblock** tail = &w.constraints[v + 1].blocks;
    for (int b = 0; b < nb; ++b) {
      const auto& entries = coefficient[v][b];
      if (entries.empty()) continue;
      auto* p = allocate<sparseblock>(1);
      *tail = p;
      tail = &p->next;
      const int m = static_cast<int>(entries.size());
      p->numentries = m;
      p->blocknum = b + 1;
      p->blocksize = w.C.blocks[b + 1].blocksize;
      p->constraintnum = v + 1;
      p->entries = allocate<double>(m + 1);
      p->iindices = allocate<int>(m + 1);
      p->jindices = allocate<int>(m + 1);
      for (int e = 0; e < m; ++e) {
        p->entries[e + 1] = entries[e].value;
        p->iindices[e + 1] = entries[e].i;
        p->jindices[e + 1] = entries[e].j;
      }
      // Sparse or dense handling is a speed choice only: dense once a block holds a good share
      // of the Schur-complement work (CSDP's own rule of thumb, restated).
      const double s = p->blocksize;
      p->issparse = !(m > 5 && 1.0 * k * m * m > 0.125 * s * s * s);
    }
  }
}

// byblocks[b]: the first constraint block on block b; nextbyblock chains the others upward.
void link_by_block(CsdpWorkspace& w) {
  w.byblocks = allocate<sparseblock*>(w.C.nblocks + 1);
  std::vector<sparseblock*> last(w.C.nblocks + 1, nullptr);
  for (int v = 1; v <= w.k; ++v)
    for (sparseblock* p = w.constraints[v].blocks; p; p = p->next) {
      p->nextbyblock = nullptr;
      if (last[p->blocknum])
        last[p->blocknum]->nextbyblock = p;
      else
        w.byblocks[p->blocknum] = p;
      last[p->blocknum] = p;
    }
}

paramstruc csdp_parameters(const LmiSettings& settings) {
  paramstruc params{};
  params.axtol = settings.tolerance;
  params.atytol = settings.tolerance;
  params.objtol = settings.tolerance;
  params.pinftol = 1.0e8;
  params.dinftol = 1.0e8;
  params.maxiter = settings.max_iterations;
  params.minstepfrac = 0.90;
  params.maxstepfrac = 0.97;
  params.minstepp = 1.0e-8;
  params.minstepd = 1.0e-8;
  params.usexzgap = 1;
  params.tweakgap = 0;
  params.affine = 0;
  params.perturbobj = 0;  // the optimum is unique (strictly convex distance): no perturbation
  params.fastmode = 0;
  return params;
}

// CSDP's start (its own, or X = Z = I, y = 0), its work space and its solve, under the lock:
// CSDP's return code; its primal and dual objectives in pobj, dobj.
int run_csdp(CsdpWorkspace& w, const LmiSettings& settings, double& pobj, double& dobj) {
  const paramstruc params = csdp_parameters(settings);
  const int printlevel = 0;  // CSDP prints nothing (initparams() is bypassed: no param.csdp)
  const int k = w.k, nb = w.C.nblocks;
  const int ldam = k % 2 == 0 ? k + 1 : k;
  const std::size_t nk = static_cast<std::size_t>(std::max(w.n, k)) + 1;
  std::lock_guard<std::mutex> lock(csdp_mutex());
  initsoln(w.n, k, w.C, w.a, w.constraints, &w.X, &w.y, &w.Z);
  if (settings.identity_start) {
    for (int b = 1; b <= nb; ++b) {
      const int size = w.X.blocks[b].blocksize;
      for (int i = 1; i <= size; ++i)
        for (int j = 1; j <= size; ++j) {
          w.X.blocks[b].data.mat[ijtok(i, j, size)] = i == j ? 1.0 : 0.0;
          w.Z.blocks[b].data.mat[ijtok(i, j, size)] = i == j ? 1.0 : 0.0;
        }
    }
    for (int v = 1; v <= k; ++v) w.y[v] = 0;
  }
  alloc_mat(w.C, &w.work1);
  alloc_mat(w.C, &w.work2);
  alloc_mat(w.C, &w.work3);
  alloc_mat(w.C, &w.Zi);
  alloc_mat(w.C, &w.dZ);
  alloc_mat(w.C, &w.dX);
  alloc_mat_packed(w.C, &w.bestx);
  alloc_mat_packed(w.C, &w.bestz);
  alloc_mat_packed(w.C, &w.cholxinv);
  alloc_mat_packed(w.C, &w.cholzinv);
  double* wv[8];
  for (double*& v : wv) v = w.vector(nk);
  double* diagO = w.vector(nk);
  double* besty = w.vector(k + 1);
  double* rhs = w.vector(k + 1);
  double* dy = w.vector(k + 1);
  double* dy1 = w.vector(k + 1);
  double* Fp = w.vector(k + 1);
  double* O = w.vector(static_cast<std::size_t>(ldam) * ldam);
  makefill(k, w.C, w.constraints, &w.fill, w.work1, printlevel);
  w.have_fill = true;
  return sdp(w.n, k, w.C, w.a, 0.0, w.constraints, w.byblocks, w.fill, w.X, w.y, w.Z, w.cholxinv, w.cholzinv, &pobj,
             &dobj, w.work1, w.work2, w.work3, wv[0], wv[1], wv[2], wv[3], wv[4], wv[5], wv[6], wv[7], diagO, w.bestx,
             besty, w.bestz, w.Zi, O, rhs, w.dZ, w.dX, dy, dy1, Fp, printlevel, params);
}

}  // namespace

std::string LmiSolution::message() const {
  switch (code) {
    case 0:
      return "ok";
    case 1:
      return "CSDP: primal infeasible (the LMI program is unbounded)";
    case 2:
      return "CSDP: dual infeasible (the LMI constraints have no solution)";
    case 3:
      return "ok (CSDP: reduced accuracy)";
    case 4:
      return "CSDP: maximum iterations reached";
    case 5:
      return "CSDP: stuck at the edge of primal feasibility";
    case 6:
      return "CSDP: stuck at the edge of dual feasibility";
    case 7:
      return "CSDP: lack of progress";
    case 8:
      return "CSDP: X, Z or O singular";
    case 9:
      return "CSDP: NaN or Inf encountered";
    default:
      return fmt::format("CSDP: return code {}", code);
  }
}

LmiProblem::LmiProblem(int variables) {
  if (variables < 1) throw std::invalid_argument("LmiProblem: at least one variable");
  objective_ = Eigen::VectorXd::Zero(variables);
  coefficient_.resize(variables);
}

int LmiProblem::add_block(const Eigen::MatrixXd& constant) {
  if (constant.rows() != constant.cols() || constant.rows() < 1)
    throw std::invalid_argument("LmiProblem::add_block: the constant term must be square");
  if (!constant.allFinite()) throw std::invalid_argument("LmiProblem::add_block: non-finite entry");
  constant_.push_back(constant);
  for (auto& c : coefficient_) c.emplace_back();
  return blocks() - 1;
}

void LmiProblem::set_coefficient(int block, int variable, const Eigen::MatrixXd& F) {
  if (block < 0 || block >= blocks() || variable < 0 || variable >= variables())
    throw std::invalid_argument("LmiProblem::set_coefficient: index out of range");
  const Eigen::Index s = constant_[block].rows();
  if (F.rows() != s || F.cols() != s)
    throw std::invalid_argument("LmiProblem::set_coefficient: size differs from the block");
  if (!F.allFinite()) throw std::invalid_argument("LmiProblem::set_coefficient: non-finite entry");
  auto& entries = coefficient_[variable][block];
  entries.clear();
  // An upper-triangle entry (i, j) stands for both (i, j) and (j, i) in CSDP.
  for (int i = 0; i < s; ++i)
    for (int j = i; j < s; ++j) {
      const double v = i == j ? F(i, i) : 0.5 * (F(i, j) + F(j, i));
      if (v != 0) entries.push_back({i + 1, j + 1, v});
    }
}

void LmiProblem::set_objective(const Eigen::VectorXd& b) {
  if (b.size() != variables()) throw std::invalid_argument("LmiProblem::set_objective: wrong size");
  if (!b.allFinite()) throw std::invalid_argument("LmiProblem::set_objective: non-finite entry");
  objective_ = b;
}

LmiSolution LmiProblem::solve(const LmiSettings& settings) const {
  const int k = variables(), nb = blocks();
  if (nb == 0) throw std::invalid_argument("LmiProblem::solve: no block");
  for (int v = 0; v < k; ++v) {
    const auto& c = coefficient_[v];
    if (std::all_of(c.begin(), c.end(), [](const auto& e) { return e.empty(); }))
      throw std::invalid_argument(fmt::format("LmiProblem::solve: variable {} enters no block", v));
  }

  CsdpWorkspace w;
  w.k = k;
  set_constant(w, constant_);
  w.a = allocate<double>(k + 1);
  for (int v = 0; v < k; ++v) w.a[v + 1] = objective_(v);
  set_constraints(w, coefficient_);
  link_by_block(w);

  double pobj = 0, dobj = 0;
  LmiSolution s;
  s.code = run_csdp(w, settings, pobj, dobj);
  s.y.resize(k);
  for (int v = 0; v < k; ++v) s.y(v) = w.y[v + 1];
  s.objective = dobj;
  s.lower_bound = pobj;
  return s;
}

}  // namespace symoro::identify::detail
