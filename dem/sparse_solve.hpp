// The sparse solvers of the static elastic solve (dem/static_solve.cpp), bit-identical at any thread count:
//   ParallelLdltSolve      the triangular solves of Eigen's sparse LDLT factorisation on several threads, equal to
//                          the bit to Ldlt::solve
//   FactorPreconditioner   an existing factorisation as the preconditioner of Eigen's Krylov solvers
//   RowOperator            a sparse matrix stored by rows whose product with a vector runs row by row on several
//                          threads, each row adding its entries in the order of the column-major product
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <omp.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace rbdem::detail {
class RowOperator;
}  // namespace rbdem::detail

// The operator below enters Eigen's products as a sparse matrix (Eigen's "matrix-free solvers" pattern).
template <>
struct Eigen::internal::traits<rbdem::detail::RowOperator>
    : public Eigen::internal::traits<Eigen::SparseMatrix<double>> {};

namespace rbdem::detail {

using SpMat = Eigen::SparseMatrix<double>;
using Ldlt = Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>>;

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

}  // namespace rbdem::detail

namespace Eigen::internal {
template <typename Rhs>
struct generic_product_impl<rbdem::detail::RowOperator, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<rbdem::detail::RowOperator, Rhs, generic_product_impl<rbdem::detail::RowOperator, Rhs>> {
  template <typename Dest>
  static void scaleAndAddTo(Dest& dst, const rbdem::detail::RowOperator& lhs, const Rhs& rhs, const double& alpha) {
    lhs.add_product(dst, rhs, alpha);
  }
};
}  // namespace Eigen::internal
