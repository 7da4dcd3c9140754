// Static elastic solve and stability limit. See static_solve.hpp.
#include "dem/static_solve.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <omp.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <fmt/format.h>

namespace rbdem {
namespace {
class RowOperator;
}  // namespace
}  // namespace rbdem

// The operator below enters Eigen's products as a sparse matrix (Eigen's "matrix-free solvers" pattern).
template <>
struct Eigen::internal::traits<rbdem::RowOperator> : public Eigen::internal::traits<Eigen::SparseMatrix<double>> {};

namespace rbdem {

namespace {

using SpMat = Eigen::SparseMatrix<double>;
using Ldlt = Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>>;

struct BondRows {
  int dof[6];
  double an[6], as[6], ar[6];  // normal opening, shear, relative rotation as functionals of the dofs
};

// Linearised kinematics of bond b at the reference configuration (the engine's bond kernel, linearised):
// delta = u_j + theta_j z x r_j - u_i - theta_i z x r_i, with r the lever arms to the edge midpoint.
BondRows bond_rows(const Engine& e, std::size_t b) {
  const Model& M = e.model();
  const int i = M.bi[b], j = M.bj[b];
  const BondFrames& f = M.frame;
  BondRows r{{3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2}, {}, {}, {}};
  const double nx = f.n0x[b], ny = f.n0y[b], tx = -ny, ty = nx;
  // z x r = (-r_y, r_x)
  const double dx[6] = {-1, 0, f.riy[b], 1, 0, -f.rjy[b]};
  const double dy[6] = {0, -1, -f.rix[b], 0, 1, f.rjx[b]};
  for (int k = 0; k < 6; ++k) {
    r.an[k] = nx * dx[k] + ny * dy[k];
    r.as[k] = tx * dx[k] + ty * dy[k];
    r.ar[k] = 0.0;
  }
  r.ar[2] = -1.0, r.ar[5] = 1.0;
  return r;
}

struct PlatenRow {
  int block;
  bool top;
  double k;      // N/m
  double rx, ry; // contact point (the boundary edge's midpoint) relative to the centroid
};

std::vector<PlatenRow> platen_rows(const Engine& e) {
  std::vector<PlatenRow> rows;
  if (!e.has_platens()) return rows;
  const Topology& topo = e.topology();
  const auto& E = topo.boundary;
  for (std::size_t k = 0; k < E.size(); ++k) {
    if (E.side[k] != Side::top && E.side[k] != Side::bottom) continue;
    const int b = E.block[k];
    rows.push_back({b, E.side[k] == Side::top, e.model().platen_kn[std::size_t(b)] * e.model().thickness * E.length[k],
                    E.mx[k] - topo.blocks.cx[b], E.my[k] - topo.blocks.cy[b]});
  }
  return rows;
}

// The stiffness on one fixed sparsity pattern: every intact bond's 6 x 6 block, every platen row's 3 x 3 block
// and the pin. Each bond knows where its 36 entries live in the value array, so a new set of linear-part states
// costs one pass over the bonds, and the symmetric factorisation's ordering and elimination tree are computed once.
//   K_sym:  parallel bond + linear part in its state (closed: normal; sticking: shear) + platens + pin.
//   K_full: K_sym + the sliding linear parts' F_s = -+ mu k_n A delta_n (a shear force driven by the normal
//           closure: non-symmetric, one rank-one term per sliding bond, inside the bond's own block).
// A weak spring on one degree of freedom that removes a rigid-body mode (a load without resultant leaves it unloaded).
struct Pin {
  int dof;
  double k;
};

class Stiffness {
 public:
  Stiffness(const Engine& e, const std::vector<PlatenRow>& platens, std::vector<Pin> pins)
      : e_(e), platens_(platens), pins_(std::move(pins)) {
    const auto& broken = e.state().broken;
    const std::size_t nbond = e.model().num_bonds();
    rows_.resize(nbond);
    k_.resize(nbond);
    std::vector<Eigen::Triplet<double>> T;
    T.reserve(nbond * 36 + platens.size() * 9 + pins_.size());
    for (std::size_t b = 0; b < nbond; ++b) {
      rows_[b] = bond_rows(e, b);
      k_[b] = e.model().stiffness(int(b));
      if (broken[b]) continue;
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) T.emplace_back(rows_[b].dof[p], rows_[b].dof[q], 1.0);
    }
    for (const auto& pr : platens)
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) T.emplace_back(3 * pr.block + p, 3 * pr.block + q, 1.0);
    for (const Pin& p : pins_) T.emplace_back(p.dof, p.dof, 1.0);
    const long n = long(3 * e.model().num_blocks());
    pattern_.resize(n, n);
    pattern_.setFromTriplets(T.begin(), T.end());
    pattern_.makeCompressed();
    slots_.assign(nbond * 36, -1);
    for (std::size_t b = 0; b < nbond; ++b) {
      if (broken[b]) continue;
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) slots_[36 * b + 6 * p + q] = slot(rows_[b].dof[p], rows_[b].dof[q]);
    }
    platen_slots_.resize(9 * platens.size());
    for (std::size_t k = 0; k < platens.size(); ++k) {
      const int d0 = 3 * platens[k].block;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) platen_slots_[9 * k + 3 * p + q] = slot(d0 + p, d0 + q);
    }
    for (const Pin& p : pins_) pin_slots_.push_back(slot(p.dof, p.dof));
  }

  const BondRows& rows(std::size_t b) const { return rows_[b]; }
  const BondStiffness& k(std::size_t b) const { return k_[b]; }
  const SpMat& pattern() const { return pattern_; }

  // Fills sym with K_sym and, when given, full with K_full for the given linear-part states (both on the pattern).
  void assemble(const std::vector<std::uint8_t>& state, SpMat& sym, SpMat* full) const {
    sym = pattern_;
    double* v = sym.valuePtr();
    std::fill(v, v + sym.nonZeros(), 0.0);
    const auto& broken = e_.state().broken;
    const std::size_t nbond = broken.size();
    for (std::size_t b = 0; b < nbond; ++b) {
      if (broken[b]) continue;
      const BondRows& r = rows_[b];
      const BondStiffness& k = k_[b];
      const std::uint8_t st = state[b];
      const double kn = k.kbnA + (st != StaticResult::open ? k.knA : 0.0);
      const double ks = k.kbsA + (st == StaticResult::stick ? k.ksA : 0.0);
      const int* s = &slots_[36 * b];
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q)
          v[s[6 * p + q]] += kn * r.an[p] * r.an[q] + ks * r.as[p] * r.as[q] + k.kbnI * r.ar[p] * r.ar[q];
    }
    const bool sticky = e_.platen_friction() > 0.0;
    for (std::size_t m = 0; m < platens_.size(); ++m) {
      const PlatenRow& p = platens_[m];
      const double ay[3] = {0.0, 1.0, p.rx};    // u_y at the contact point
      const double ax[3] = {1.0, 0.0, -p.ry};   // u_x at the contact point (sticking platens)
      const double ks = sticky ? p.k / e_.model().law[e_.model().block_material[std::size_t(p.block)]].kappa : 0.0;
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) v[platen_slots_[9 * m + 3 * a + c]] += p.k * ay[a] * ay[c] + ks * ax[a] * ax[c];
    }
    for (std::size_t k = 0; k < pins_.size(); ++k) v[pin_slots_[k]] += pins_[k].k;
    if (!full) return;
    *full = sym;
    double* w = full->valuePtr();
    for (std::size_t b = 0; b < nbond; ++b) {
      const std::uint8_t st = state[b];
      if (broken[b] || (st != StaticResult::slip_positive && st != StaticResult::slip_negative)) continue;
      // sliding: F_s = sign(delta_s) mu k_n A delta_n
      const double c = -(st == StaticResult::slip_positive ? 1.0 : -1.0) * k_[b].mu * k_[b].knA;
      const BondRows& r = rows_[b];
      const int* s = &slots_[36 * b];
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) w[s[6 * p + q]] += c * r.as[p] * r.an[q];
    }
  }

 private:
  int slot(int row, int col) const {
    const int* inner = pattern_.innerIndexPtr();
    const int* begin = inner + pattern_.outerIndexPtr()[col];
    const int* end = inner + pattern_.outerIndexPtr()[col + 1];
    return int(std::lower_bound(begin, end, row) - inner);
  }

  const Engine& e_;
  const std::vector<PlatenRow>& platens_;
  std::vector<Pin> pins_;
  std::vector<BondRows> rows_;
  std::vector<BondStiffness> k_;
  std::vector<int> slots_, platen_slots_;
  std::vector<int> pin_slots_;
  SpMat pattern_;
};

// The solve with an LDLT factorisation (P^T L D L^T P) on several threads, equal to the bit to Ldlt::solve.
//
// The columns of L form the elimination tree (a column's first entry below the diagonal is its parent; every entry
// of column j lies on the path from j to the root). Disjoint subtrees do not meet in either triangular solve, so
// each thread takes whole subtrees, and one thread does the nodes above them (the "top", ancestors only). Every
// unknown gets the same operations in the same order as in Eigen's sequential solves:
// - L y = b, which Eigen runs by columns (column j, once y_j is final and if it is not zero, subtracts y_j L_ij
//   from each y_i below): a thread runs its subtrees' columns in ascending order but updates only the rows of the
//   same subtree; a top row i then subtracts y_j L_ij, j ascending, for each of its entries with y_j not zero;
// - L^T x = z, which Eigen runs by rows of L^T (x_i = z_i - sum of L_ki x_k, k ascending along column i): the top
//   rows first, in descending order, then each thread its subtrees' rows in descending order.
// The permutations and D^-1 are Eigen's own expressions.
class ParallelLdltSolve {
 public:
  // The subtrees for `threads` threads on the pattern of `factor` (unchanged by later factorisations that keep
  // the symbolic analysis).
  void plan(const Ldlt& factor, int threads) {
    threads_ = threads;
    if (threads <= 1) return;
    const SpMat& L = factor.matrixL().nestedExpression();
    const int n = int(L.cols());
    const int* Lp = L.outerIndexPtr();
    const int* Li = L.innerIndexPtr();
    const std::size_t N = std::size_t(n);
    std::vector<int> parent(N, -1);
    std::vector<double> work(N);  // of a subtree: the entries of its columns, plus one per column
    for (int j = 0; j < n; ++j) {
      for (int p = Lp[j]; p < Lp[j + 1]; ++p)
        if (Li[p] > j) {
          parent[std::size_t(j)] = Li[p];
          break;
        }
      work[std::size_t(j)] += double(Lp[j + 1] - Lp[j] + 1);
      if (parent[std::size_t(j)] >= 0) work[std::size_t(parent[std::size_t(j)])] += work[std::size_t(j)];
    }
    std::vector<std::vector<int>> children(N);
    std::vector<int> frontier;  // the roots of the subtrees below the top
    for (int j = 0; j < n; ++j)
      (parent[std::size_t(j)] >= 0 ? children[std::size_t(parent[std::size_t(j)])] : frontier).push_back(j);
    // Subtrees packed heaviest first onto the least loaded thread; the heaviest load.
    std::vector<int> owner(N, -2);
    auto pack = [&](std::vector<int> roots, bool assign) {
      std::stable_sort(roots.begin(), roots.end(),
                       [&](int a, int b) { return work[std::size_t(a)] > work[std::size_t(b)]; });
      std::vector<double> load(std::size_t(threads), 0.0);
      for (int r : roots) {
        const auto t = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
        load[t] += work[std::size_t(r)];
        if (assign) owner[std::size_t(r)] = int(t);
      }
      return *std::max_element(load.begin(), load.end());
    };
    // Split the heaviest subtree (its root joins the top) while that may shorten the estimate, the top's work
    // plus the heaviest thread's; keep the best split seen.
    std::vector<int> top_nodes;
    double top_work = 0.0, best = pack(frontier, false);
    std::size_t best_splits = 0;
    while (!frontier.empty() && frontier.size() <= 256 && top_work < best) {
      const auto heaviest = std::max_element(frontier.begin(), frontier.end(), [&](int a, int b) {
        return work[std::size_t(a)] < work[std::size_t(b)];
      });
      const int r = *heaviest;
      frontier.erase(heaviest);
      top_nodes.push_back(r);
      top_work += double(Lp[r + 1] - Lp[r] + 1);
      for (int c : children[std::size_t(r)]) frontier.push_back(c);
      const double e = top_work + pack(frontier, false);
      if (e < best) best = e, best_splits = top_nodes.size();
    }
    std::vector<std::uint8_t> in_top(N, 0);
    for (std::size_t k = 0; k < best_splits; ++k) in_top[std::size_t(top_nodes[k])] = 1;
    std::vector<int> roots;
    for (int j = 0; j < n; ++j)
      if (!in_top[std::size_t(j)] && (parent[std::size_t(j)] < 0 || in_top[std::size_t(parent[std::size_t(j)])]))
        roots.push_back(j);
    pack(roots, true);
    for (int j = 0; j < n; ++j)
      if (in_top[std::size_t(j)]) owner[std::size_t(j)] = -1;
    root_.assign(N, -1);
    for (int r : roots) root_[std::size_t(r)] = r;
    for (int j = n - 1; j >= 0; --j)
      if (owner[std::size_t(j)] == -2) {
        const int pj = parent[std::size_t(j)];
        owner[std::size_t(j)] = owner[std::size_t(pj)];
        root_[std::size_t(j)] = root_[std::size_t(pj)];
      }
    columns_.assign(std::size_t(threads), {});
    top_.clear();
    for (int j = 0; j < n; ++j)
      (owner[std::size_t(j)] >= 0 ? columns_[std::size_t(owner[std::size_t(j)])] : top_).push_back(j);
    // The top rows' entries (column, position in L), each row's in ascending column order.
    std::vector<int> slot_of(N, -1);
    for (std::size_t k = 0; k < top_.size(); ++k) slot_of[std::size_t(top_[k])] = int(k);
    top_offset_.assign(top_.size() + 1, 0);
    for (int j = 0; j < n; ++j)
      for (int p = Lp[j]; p < Lp[j + 1]; ++p)
        if (Li[p] > j && slot_of[std::size_t(Li[p])] >= 0) ++top_offset_[std::size_t(slot_of[std::size_t(Li[p])]) + 1];
    for (std::size_t k = 0; k < top_.size(); ++k) top_offset_[k + 1] += top_offset_[k];
    top_col_.resize(std::size_t(top_offset_.back())), top_pos_.resize(std::size_t(top_offset_.back()));
    std::vector<int> next(top_offset_.begin(), top_offset_.end() - 1);
    for (int j = 0; j < n; ++j)
      for (int p = Lp[j]; p < Lp[j + 1]; ++p)
        if (Li[p] > j && slot_of[std::size_t(Li[p])] >= 0) {
          const int at = next[std::size_t(slot_of[std::size_t(Li[p])])]++;
          top_col_[std::size_t(at)] = j, top_pos_[std::size_t(at)] = p;
        }
    take_values(factor);
  }
  // The top rows' values of a new factorisation on the planned pattern: gathered once, so that each solve reads
  // them in order rather than scattered over L.
  void take_values(const Ldlt& factor) {
    if (threads_ <= 1) return;
    const double* Lx = factor.matrixL().nestedExpression().valuePtr();
    top_val_.resize(top_pos_.size());
    for (std::size_t q = 0; q < top_pos_.size(); ++q) top_val_[q] = Lx[top_pos_[q]];
  }
  int threads() const { return threads_; }

  Eigen::VectorXd solve(const Ldlt& factor, const Eigen::VectorXd& b) const {
    if (threads_ <= 1 || factor.info() != Eigen::Success) return factor.solve(b);
    const SpMat& L = factor.matrixL().nestedExpression();
    const int* Lp = L.outerIndexPtr();
    const int* Li = L.innerIndexPtr();
    const double* Lx = L.valuePtr();
    Eigen::VectorXd x = factor.permutationP() * b;
    double* y = x.data();
#pragma omp parallel num_threads(threads_)
    {
      // My subtrees' columns; all of them on the first thread of a team smaller than planned (as inside another
      // parallel region): the subtrees are independent, so any order of them gives the same numbers.
      const int t = omp_get_thread_num();
      const bool planned = omp_get_num_threads() == threads_;
      const int first = planned ? t : (t == 0 ? 0 : threads_), end = planned ? t + 1 : threads_;
      for (int k = first; k < end; ++k)
        for (int j : columns_[std::size_t(k)]) {  // L y = b in the subtrees
          const double yj = y[j];
          if (yj == 0.0) continue;
          const int r = root_[std::size_t(j)];
          for (int p = Lp[j]; p < Lp[j + 1] && Li[p] <= r; ++p)
            if (Li[p] > j) y[Li[p]] -= yj * Lx[p];
        }
#pragma omp barrier
#pragma omp master
      {
        for (std::size_t k = 0; k < top_.size(); ++k) {  // L y = b in the top rows
          double yi = y[top_[k]];
          for (int q = top_offset_[k]; q < top_offset_[k + 1]; ++q) {
            const double yj = y[top_col_[std::size_t(q)]];
            if (yj != 0.0) yi -= yj * top_val_[std::size_t(q)];
          }
          y[top_[k]] = yi;
        }
        x = factor.vectorD().asDiagonal().inverse() * x;
        for (std::size_t k = top_.size(); k-- > 0;) y[top_[k]] = backward_row(top_[k], Lp, Li, Lx, y);
      }
#pragma omp barrier
      for (int k = first; k < end; ++k)
        for (auto j = columns_[std::size_t(k)].rbegin(); j != columns_[std::size_t(k)].rend(); ++j)
          y[*j] = backward_row(*j, Lp, Li, Lx, y);
    }
    return factor.permutationPinv() * x;
  }

 private:
  // Row i of L^T x = z: x_i = z_i - sum of L_ki x_k over column i's entries below the diagonal, in their order.
  static double backward_row(int i, const int* Lp, const int* Li, const double* Lx, const double* x) {
    double xi = x[i];
    for (int p = Lp[i]; p < Lp[i + 1]; ++p)
      if (Li[p] > i) xi -= Lx[p] * x[Li[p]];
    return xi;
  }

  int threads_ = 0;
  std::vector<std::vector<int>> columns_;  // per thread: the columns of its subtrees, ascending
  std::vector<int> root_;                  // per column in a subtree: that subtree's root
  std::vector<int> top_;                   // the top's columns, ascending
  std::vector<int> top_offset_, top_col_, top_pos_;  // the top rows' entries of L: column and position
  std::vector<double> top_val_;                      // and value
};

// A preconditioner for Eigen's Krylov solvers that applies an existing factorisation of K_sym.
class FactorPreconditioner {
 public:
  FactorPreconditioner() = default;
  template <typename M> explicit FactorPreconditioner(const M&) {}
  template <typename M> FactorPreconditioner& analyzePattern(const M&) { return *this; }
  template <typename M> FactorPreconditioner& factorize(const M&) { return *this; }
  template <typename M> FactorPreconditioner& compute(const M&) { return *this; }
  template <typename Rhs> Eigen::VectorXd solve(const Rhs& b) const { return solver_->solve(*factor_, b); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
  void use(const Ldlt& factor, const ParallelLdltSolve& solver) { factor_ = &factor, solver_ = &solver; }

 private:
  const Ldlt* factor_ = nullptr;
  const ParallelLdltSolve* solver_ = nullptr;
};

// K_full as the operator of BiCGSTAB: the same matrix stored by rows, so that its product with a vector runs row
// by row on several threads. Each row adds its entries in column order onto the destination's entry, which is the
// order in which the column-major product adds them, so the result is the same to the bit at any thread count.
class RowOperator : public Eigen::EigenBase<RowOperator> {
 public:
  using Scalar = double;
  using RealScalar = double;
  using StorageIndex = int;
  enum { ColsAtCompileTime = Eigen::Dynamic, MaxColsAtCompileTime = Eigen::Dynamic, IsRowMajor = false };

  // The row layout of `pattern` (column-major): where each of its entries goes.
  explicit RowOperator(const SpMat& pattern) : n_(pattern.rows()) {
    const long nnz = pattern.nonZeros();
    outer_.assign(std::size_t(n_) + 1, 0), inner_.resize(std::size_t(nnz)), to_row_.resize(std::size_t(nnz));
    values_.assign(std::size_t(nnz), 0.0);
    const int* co = pattern.outerIndexPtr();
    const int* ci = pattern.innerIndexPtr();
    for (long k = 0; k < nnz; ++k) ++outer_[std::size_t(ci[k]) + 1];
    for (long i = 0; i < n_; ++i) outer_[std::size_t(i) + 1] += outer_[std::size_t(i)];
    std::vector<int> next(outer_.begin(), outer_.end() - 1);
    for (long j = 0; j < pattern.cols(); ++j)  // columns in order: each row's entries in column order
      for (int k = co[j]; k < co[j + 1]; ++k) {
        const int at = next[std::size_t(ci[k])]++;
        inner_[std::size_t(at)] = int(j), to_row_[std::size_t(k)] = at;
      }
  }
  // The values of `full` (on the pattern given to the constructor), and the threads of the next products.
  void set(const SpMat& full, int threads) {
    const double* v = full.valuePtr();
    for (std::size_t k = 0; k < to_row_.size(); ++k) values_[std::size_t(to_row_[k])] = v[k];
    threads_ = threads;
  }

  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  // A default product, as for a sparse matrix: BiCGSTAB's "rhs - A x" then takes the same path (rhs, minus the
  // product added entry by entry).
  template <typename Rhs>
  Eigen::Product<RowOperator, Rhs> operator*(const Eigen::MatrixBase<Rhs>& x) const {
    return Eigen::Product<RowOperator, Rhs>(*this, x.derived());
  }

  // dst += alpha A x, entry by entry as the column-major product computes it (x is read in place when it is a
  // plain vector, as it is in BiCGSTAB).
  template <typename Dest, typename Rhs>
  void add_product(Dest& dst, const Rhs& x, double alpha) const {
    const Eigen::Ref<const Eigen::VectorXd> xv(x);
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1)
    for (long i = 0; i < n_; ++i) {
      double acc = dst.coeff(i);
      for (int k = outer_[std::size_t(i)]; k < outer_[std::size_t(i) + 1]; ++k)
        acc += values_[std::size_t(k)] * (alpha * xv[inner_[std::size_t(k)]]);
      dst.coeffRef(i) = acc;
    }
  }

 private:
  long n_;
  std::vector<int> outer_, inner_, to_row_;
  std::vector<double> values_;
  int threads_ = 1;
};

}  // namespace
}  // namespace rbdem

namespace Eigen::internal {
template <typename Rhs>
struct generic_product_impl<rbdem::RowOperator, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<rbdem::RowOperator, Rhs, generic_product_impl<rbdem::RowOperator, Rhs>> {
  template <typename Dest>
  static void scaleAndAddTo(Dest& dst, const rbdem::RowOperator& lhs, const Rhs& rhs, const double& alpha) {
    lhs.add_product(dst, rhs, alpha);
  }
};
}  // namespace Eigen::internal

namespace rbdem {

StaticResult solve_static(const Engine& e, const StaticOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const Model& M = e.model();
  const auto& broken = e.state().broken;
  const std::size_t nb = M.num_blocks(), nbond = M.num_bonds();
  const double delta = options.platens ? options.platen_displacement : 0.0;
  const auto platens = options.platens ? platen_rows(e) : std::vector<PlatenRow>{};
  if (options.platens && platens.empty())
    throw std::invalid_argument("static solve: the specimen has no edges on the platens (check the mesh boundary)");
  if (!options.load.empty() && options.load.size() != 3 * nb)
    throw std::invalid_argument("static solve: the load has " + std::to_string(options.load.size()) +
                                " entries; it needs 3 per block (fx, fy, moment)");
  if (!options.platens && options.anchors.empty())
    throw std::invalid_argument("static solve: without platens the specimen needs an anchor block (rigid modes)");
  StaticResult r;
  r.platen_displacement = delta;
  r.dofs = 3 * nb;
  r.linear_state.assign(nbond, StaticResult::stick);

  // Weak springs for the rigid-body modes the supports leave free: the x translation between frictionless platens;
  // without platens all three dofs of each anchor block. A load without resultant leaves them unloaded.
  std::vector<Pin> pins;
  if (options.platens) {
    double mean_diag = 0;
    for (const auto& p : platens) mean_diag += p.k;
    if (!(e.platen_friction() > 0.0)) pins.push_back({0, 1e-3 * mean_diag / double(platens.size())});
  } else {
    double k = 0, L2 = 0;
    for (std::size_t b = 0; b < nbond; ++b) k += M.frame.K[b], L2 += M.frame.L[b] * M.frame.L[b];
    k /= double(std::max<std::size_t>(nbond, 1)), L2 /= double(std::max<std::size_t>(nbond, 1));
    for (int b : options.anchors)
      pins.insert(pins.end(), {{3 * b, 1e-3 * k}, {3 * b + 1, 1e-3 * k}, {3 * b + 2, 1e-3 * k * L2}});
  }

  Eigen::VectorXd f = Eigen::VectorXd::Zero(long(3 * nb));
  for (std::size_t k = 0; k < options.load.size(); ++k) f[long(k)] = options.load[k];
  for (const auto& p : platens)
    if (p.top) {  // overlap = u_y(point) + delta: energy k (u_y + delta)^2 / 2 gives the load -k delta
      f[3 * p.block + 1] -= p.k * delta;
      f[3 * p.block + 2] -= p.k * delta * p.rx;
    }
  // Each active-set iteration solves K_full(states) u = f. The first state (every linear part closed and
  // sticking) is symmetric: one sparse LDLT (AMD ordering) solves it exactly. Later states differ by the bonds
  // that opened or slide, so BiCGSTAB preconditioned by that factorisation converges in a few iterations from
  // the previous solution; if it does not, the current K_sym is factorised (same symbolic analysis) and BiCGSTAB
  // retried, and sparse LU of K_full is the last resort.
  const Stiffness stiffness(e, platens, pins);
  SpMat K_sym, K_full;
  Ldlt factor;
  factor.analyzePattern(stiffness.pattern());
  ParallelLdltSolve solves;  // the triangular solves on the threads the products have (planned when that changes)
  auto factorise = [&]() {
    factor.factorize(K_sym);
    if (factor.info() != Eigen::Success)
      throw std::runtime_error("static solve: the bonded-block stiffness is singular (a block without bonds or "
                               "platen contact? check the mesh)");
    solves.take_values(factor);
  };
  auto solver = [&]() -> const ParallelLdltSolve& {
    const int threads = options.threads ? std::max(options.threads->load(std::memory_order_relaxed), 1) : 1;
    if (solves.threads() != threads) solves.plan(factor, threads);
    return solves;
  };
  RowOperator K_rows(stiffness.pattern());
  Eigen::BiCGSTAB<RowOperator, FactorPreconditioner> krylov;
  krylov.setTolerance(options.krylov_tolerance);
  krylov.setMaxIterations(100);
  auto iterate = [&](Eigen::VectorXd& x) {
    K_rows.set(K_full, options.threads ? std::max(options.threads->load(std::memory_order_relaxed), 1) : 1);
    krylov.compute(K_rows);
    krylov.preconditioner().use(factor, solver());
    x = krylov.solveWithGuess(f, x);
    r.krylov_iterations += int(krylov.iterations());
    return krylov.info() == Eigen::Success;
  };
  Eigen::VectorXd u;
  // Bonds whose state flips back and forth between iterations are few and near a state boundary, where both
  // states give nearly the same forces; stop when at most this many change. A linear part that has changed its
  // state twice keeps the state it has: near the boundary no state is consistent for every bond at once (a bond
  // opening unloads a neighbour, which then closes it again), and without the hold the iteration cycles through
  // the same few dozen bonds until max_iterations (30 solves where about 5 settle it; docs/performance.md).
  const std::size_t settled = nbond / 10000;
  std::vector<std::uint8_t> flips(nbond, 0);
  for (int it = 0; it < options.max_iterations; ++it) {
    r.active_set_iterations = it + 1;
    stiffness.assemble(r.linear_state, K_sym, &K_full);
    if (it == 0) {
      factorise();
      u = solver().solve(factor, f);
    } else if (const Eigen::VectorXd guess = u; !iterate(u)) {
      factorise();
      u = guess;
      if (!iterate(u)) {
        Eigen::SparseLU<SpMat> lu;
        lu.compute(K_full);
        if (lu.info() != Eigen::Success)
          throw std::runtime_error("static solve: the bonded-block stiffness is singular (a block without bonds or "
                                   "platen contact? check the mesh)");
        u = lu.solve(f);
        ++r.direct_fallbacks;
      }
    }
    if (options.linear_parts_always_closed) break;
    std::size_t changed = 0;
    for (std::size_t b = 0; b < nbond; ++b) {
      if (broken[b]) continue;
      const BondRows& row = stiffness.rows(b);
      double dn = 0, ds = 0;
      for (int k = 0; k < 6; ++k) dn += row.an[k] * u[row.dof[k]], ds += row.as[k] * u[row.dof[k]];
      std::uint8_t st = StaticResult::open;
      if (dn < 0.0) {
        const BondStiffness& k = stiffness.k(b);
        st = !k.slip_bonded || std::abs(k.ksA * ds) <= k.mu * (-k.knA * dn)
                 ? StaticResult::stick
                 : (ds > 0 ? StaticResult::slip_positive : StaticResult::slip_negative);
      }
      if (st == r.linear_state[b]) continue;
      if (flips[b] >= 2) {
        ++r.held_bonds;
        continue;
      }
      r.linear_state[b] = st, ++flips[b], ++changed;
    }
    if (changed <= settled) break;
  }
  for (std::size_t b = 0; b < nbond; ++b) {
    if (broken[b]) continue;
    if (r.linear_state[b] == StaticResult::open) ++r.open_bonds;
    else if (r.linear_state[b] != StaticResult::stick) ++r.sliding_bonds;
  }

  r.ux.resize(nb), r.uy.resize(nb), r.rotation.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) r.ux[b] = u[3 * b], r.uy[b] = u[3 * b + 1], r.rotation[b] = u[3 * b + 2];
  r.platen_fs.assign(nb, 0.0);
  for (const auto& p : platens) {
    const double uyp = u[3 * p.block + 1] + p.rx * u[3 * p.block + 2];
    if (p.top) r.top_force += p.k * (uyp + delta);
    else r.bottom_force += -p.k * uyp;
    if (e.platen_friction() > 0.0) {  // sticking platen: shear along t = perp(n), n = +-y into the platen
      const double uxp = u[3 * p.block] - p.ry * u[3 * p.block + 2];
      const double tx = p.top ? -1.0 : 1.0;
      r.platen_fs[p.block] += -(p.k / M.law[M.block_material[std::size_t(p.block)]].kappa) * uxp * tx;
    }
  }
  const double H = e.model().height, W = e.model().width, t = e.model().thickness;
  r.apparent_modulus = delta > 0.0 ? (r.top_force / (W * t)) / (delta / H) : 0.0;

  // Bond forces and the load factor of the first bond failure (all forces scale with the displacement).
  r.fn_b.resize(nbond), r.fs_b.resize(nbond), r.m_b.resize(nbond), r.fs_lin.assign(nbond, 0.0);
  r.first_break_factor = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < nbond; ++b) {
    if (broken[b]) continue;
    const BondRows row = bond_rows(e, b);
    double dn = 0, ds = 0, dr = 0;
    for (int k = 0; k < 6; ++k) dn += row.an[k] * u[row.dof[k]], ds += row.as[k] * u[row.dof[k]], dr += row.ar[k] * u[row.dof[k]];
    const BondStiffness k = e.model().stiffness(int(b));
    const double fn = -k.kbnA * dn, fs = -k.kbsA * ds, m = -k.kbnI * dr;
    r.fn_b[b] = fn, r.fs_b[b] = fs, r.m_b[b] = m;
    const std::uint8_t ls = r.linear_state[b];
    if (ls == StaticResult::stick) r.fs_lin[b] = -k.ksA * ds;
    else if (ls != StaticResult::open) r.fs_lin[b] = (ls == StaticResult::slip_positive ? -1.0 : 1.0) * k.mu * (-k.knA * dn);
    // The parallel bond's own strength test (dem/laws/parallel_bond.hpp), solved for the load factor.
    BondStrength st = M.law[M.material[b]].bond.strength;
    st.sigma_c *= M.frame.strength_factor[b], st.cohesion *= M.frame.strength_factor[b];
    const double lam = st.first_break_factor(fn, fs, m, k.A, k.I, 0.5 * k.L);
    if (lam < r.first_break_factor) r.first_break_factor = lam, r.first_break_bond = int(b);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void apply_static_state(Engine& e, const StaticResult& st, double factor, double velocity) {
  // Displacement per second per unit of the static field; a state not driven by the platens is put at rest.
  const double rate = st.platen_displacement > 0.0 ? velocity / st.platen_displacement : 0.0;
  const Model& M = e.model();
  e.edit([&](ModelState& s) {
    for (std::size_t b = 0; b < M.num_blocks(); ++b) {
      s.x[b] = M.x0[b] + factor * st.ux[b];
      s.y[b] = M.y0[b] + factor * st.uy[b];
      s.theta[b] = factor * st.rotation[b];
      s.vx[b] = rate * st.ux[b], s.vy[b] = rate * st.uy[b], s.omega[b] = rate * st.rotation[b];
    }
    for (std::size_t b = 0; b < M.num_bonds(); ++b) s.fs_lin[b] = factor * st.fs_lin[b];
    // A block's platen shear goes to the platen it touches, found from its position.
    const double mid = 0.5 * (s.top_y + M.ymin);
    for (std::size_t b = 0; b < M.num_blocks(); ++b)
      if (st.platen_fs[b] != 0.0) (s.y[b] > mid ? s.top_fs : s.bottom_fs)[b] = factor * st.platen_fs[b];
    const double d = factor * st.platen_displacement;
    s.top_y = M.ymax - d;
    s.time = d > 0.0 ? d / velocity : 0.0;
  });
}

double stability_limit(const Engine& e, int iterations, int threads_wanted) {
  const Model& M = e.model();
  const std::size_t nb = M.num_blocks();
  std::vector<std::uint8_t> sticking(M.num_bonds(), StaticResult::stick);
  const auto platens = platen_rows(e);
  SpMat K;
  Stiffness(e, platens, {}).assemble(sticking, K, nullptr);
  Eigen::VectorXd inv_sqrt_m(long(3 * nb));
  for (std::size_t b = 0; b < nb; ++b) {
    inv_sqrt_m[3 * b] = inv_sqrt_m[3 * b + 1] = 1.0 / std::sqrt(M.mass[b]);
    inv_sqrt_m[3 * b + 2] = 1.0 / std::sqrt(M.inertia[b]);
  }
  // Power iteration on M^-1/2 K M^-1/2 from a deterministic rough start. The product runs over the rows of K on the
  // engine's threads; each row sums its entries in column order, as a serial product of K would, so the limit is
  // the same to the last bit at any thread count.
  using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  const RowMat Kr = K;
  const long n = long(3 * nb);
  Eigen::VectorXd v(n), y(n), w(n);
  for (long k = 0; k < v.size(); ++k) v[k] = std::sin(12.9898 * double(k) + 1.0);
  v.normalize();
  double lambda = 0;
  const int threads = std::max(1, threads_wanted > 0 ? threads_wanted : e.threads());
  for (int it = 0; it < iterations; ++it) {
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) y[i] = inv_sqrt_m[i] * v[i];
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        double sum = 0.0;
        for (RowMat::InnerIterator k(Kr, i); k; ++k) sum += k.value() * y[k.index()];
        w[i] = inv_sqrt_m[i] * sum;
      }
    }
    lambda = v.dot(w);  // the reductions stay serial: their order is Eigen's at any thread count
    const double norm = w.norm();
    if (!(norm > 0)) break;
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
    for (long i = 0; i < n; ++i) v[i] = w[i] / norm;
  }
  return 2.0 / std::sqrt(lambda);
}

std::vector<double> jacket_load(const Engine& engine, double pressure) {
  const Model& M = engine.model();
  std::vector<double> f(3 * M.num_blocks(), 0.0);
  const double pt = pressure * M.thickness;
  const auto& J = M.jacket;
  for (std::size_t e = 0; e < J.size(); ++e) {
    const std::size_t b = std::size_t(J.block[e]);
    // The same force as the jacket stage (dem/stages/jacket.cpp) in the reference configuration.
    const double fx = -pt * (J.by[e] - J.ay[e]), fy = pt * (J.bx[e] - J.ax[e]);
    const double rx = 0.5 * (J.ax[e] + J.bx[e]), ry = 0.5 * (J.ay[e] + J.by[e]);
    f[3 * b] += fx, f[3 * b + 1] += fy, f[3 * b + 2] += rx * fy - ry * fx;
  }
  return f;
}

StaticResult superpose(const StaticResult& a, double fa, const StaticResult& b, double fb) {
  StaticResult r = b;
  auto mix = [&](std::vector<double>& out, const std::vector<double>& x, const std::vector<double>& y) {
    out.resize(y.size());
    for (std::size_t k = 0; k < y.size(); ++k) out[k] = fa * x[k] + fb * y[k];
  };
  mix(r.ux, a.ux, b.ux), mix(r.uy, a.uy, b.uy), mix(r.rotation, a.rotation, b.rotation);
  mix(r.fn_b, a.fn_b, b.fn_b), mix(r.fs_b, a.fs_b, b.fs_b), mix(r.m_b, a.m_b, b.m_b);
  mix(r.fs_lin, a.fs_lin, b.fs_lin), mix(r.platen_fs, a.platen_fs, b.platen_fs);
  r.top_force = fa * a.top_force + fb * b.top_force;
  r.bottom_force = fa * a.bottom_force + fb * b.bottom_force;
  r.platen_displacement = fa * a.platen_displacement + fb * b.platen_displacement;
  r.first_break_factor = std::numeric_limits<double>::infinity();
  r.first_break_bond = -1;
  return r;
}

double first_break_along(const Engine& e, const StaticResult& base, const StaticResult& inc, int* bond) {
  const Model& M = e.model();
  const BondFrames& f = M.frame;
  double best = std::numeric_limits<double>::infinity();
  int which = -1;
  for (std::size_t b = 0; b < M.num_bonds(); ++b) {
    if (e.state().broken[b]) continue;
    const double lam = affine_break_factor(f.tension_limit[b], f.cohesion_A[b], f.tan_phi[b], f.beta_m[b], f.inv_L[b],
                                           base.fn_b[b], base.fs_b[b], base.m_b[b], inc.fn_b[b], inc.fs_b[b],
                                           inc.m_b[b]);
    if (lam < best) best = lam, which = int(b);
  }
  if (bond) *bond = which;
  return best;
}

void apply_static_path(Engine& e, const StaticResult& base, const StaticResult& inc, double lambda, double velocity) {
  const StaticResult st = superpose(base, 1.0, inc, lambda);
  const double rate = velocity / inc.platen_displacement;  // the increment per second
  const Model& M = e.model();
  e.edit([&](ModelState& s) {
    for (std::size_t b = 0; b < M.num_blocks(); ++b) {
      s.x[b] = M.x0[b] + st.ux[b];
      s.y[b] = M.y0[b] + st.uy[b];
      s.theta[b] = st.rotation[b];
      s.vx[b] = rate * inc.ux[b], s.vy[b] = rate * inc.uy[b], s.omega[b] = rate * inc.rotation[b];
    }
    s.fs_lin = st.fs_lin;
    const double mid = 0.5 * (s.top_y + M.ymin);
    for (std::size_t b = 0; b < M.num_blocks(); ++b)
      if (st.platen_fs[b] != 0.0) (s.y[b] > mid ? s.top_fs : s.bottom_fs)[b] = st.platen_fs[b];
    s.top_y = M.ymax - st.platen_displacement;
    s.time = lambda * inc.platen_displacement / velocity;
  });
}

}  // namespace rbdem
