// Static elastic solve and stability limit of the 2D model. See static_solve.hpp.
#include "dem/static_solve.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <omp.h>

#include <Eigen/SparseLU>
#include <fmt/format.h>

#include "dem/sparse_solve.hpp"

namespace rbdem {

namespace {

using detail::FactorPreconditioner;
using detail::Ldlt;
using detail::ParallelLdltSolve;
using detail::RowOperator;
using detail::SpMat;
using PlatenRow = StaticSupports2::PlatenRow;

struct BondRows {
  int dof[6];
  double an[6], as[6], ar[6];  // normal opening, shear, relative rotation as functionals of the dofs
};

// Linearised kinematics of bond b at the reference configuration (the engine's bond kernel, linearised):
// delta = u_j + theta_j z x r_j - u_i - theta_i z x r_i, with r the lever arms to the edge midpoint.
BondRows bond_rows(const Model<2>& M, std::size_t b) {
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

// What the attached boundary components add to the solve: the platens' rows (unless left out), fixed blocks, loads.
StaticSupports2 supports_of(const Engine<2>& e, bool platens) {
  StaticSupports2 s;
  for (const BoundaryHooks<2>* h : e.hooks()) h->static_supports(e.model(), s);
  if (!platens) s.platen_rows.clear(), s.sticky_platens = false;
  return s;
}

// A weak spring on one degree of freedom that removes a rigid-body mode (a load without resultant leaves it unloaded).
struct Pin {
  int dof;
  double k;
};

// The stiffness on one fixed sparsity pattern: every intact bond's 6 x 6 block, every platen row's 3 x 3 block
// and the pins. Each bond knows where its 36 entries live in the value array, so a new set of linear-part states
// costs one pass over the bonds, and the symmetric factorisation's ordering and elimination tree are computed once.
//   K_sym:  parallel bond + linear part in its state (closed: normal; sticking: shear) + platens + pins.
//   K_full: K_sym + the sliding linear parts' F_s = -+ mu k_n A delta_n (a shear force driven by the normal
//           closure: non-symmetric, one rank-one term per sliding bond, inside the bond's own block).
// The dofs of fixed blocks (block groups) are eliminated: their rows and columns are zero but for a unit diagonal.
class Stiffness {
 public:
  Stiffness(const Engine<2>& e, const StaticSupports2& supports, std::vector<Pin> pins)
      : e_(e), platens_(supports.platen_rows), sticky_(supports.sticky_platens), pins_(std::move(pins)) {
    const auto& broken = e.state().broken;
    const std::size_t nbond = e.model().num_bonds();
    rows_.resize(nbond);
    k_.resize(nbond);
    std::vector<Eigen::Triplet<double>> T;
    T.reserve(nbond * 36 + platens_.size() * 9 + pins_.size());
    for (std::size_t b = 0; b < nbond; ++b) {
      rows_[b] = bond_rows(e.model(), b);
      k_[b] = e.model().stiffness(int(b));
      if (broken[b]) continue;
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) T.emplace_back(rows_[b].dof[p], rows_[b].dof[q], 1.0);
    }
    for (const auto& pr : platens_)
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) T.emplace_back(3 * pr.block + p, 3 * pr.block + q, 1.0);
    for (const Pin& p : pins_) T.emplace_back(p.dof, p.dof, 1.0);
    const long n = long(3 * e.model().num_blocks());
    for (int b : supports.fixed)
      for (int d = 0; d < 3; ++d) T.emplace_back(3 * b + d, 3 * b + d, 1.0);
    pattern_.resize(n, n);
    pattern_.setFromTriplets(T.begin(), T.end());
    pattern_.makeCompressed();
    slots_.assign(nbond * 36, -1);
    for (std::size_t b = 0; b < nbond; ++b) {
      if (broken[b]) continue;
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) slots_[36 * b + 6 * p + q] = slot(rows_[b].dof[p], rows_[b].dof[q]);
    }
    platen_slots_.resize(9 * platens_.size());
    for (std::size_t k = 0; k < platens_.size(); ++k) {
      const int d0 = 3 * platens_[k].block;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) platen_slots_[9 * k + 3 * p + q] = slot(d0 + p, d0 + q);
    }
    for (const Pin& p : pins_) pin_slots_.push_back(slot(p.dof, p.dof));
    eliminate(supports.fixed);
  }

  const BondRows& rows(std::size_t b) const { return rows_[b]; }
  const BondStiffness& k(std::size_t b) const { return k_[b]; }
  const SpMat& pattern() const { return pattern_; }
  const std::vector<std::uint8_t>& fixed_dof() const { return fixed_dof_; }

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
    const Model<2>& M = e_.model();
    for (std::size_t m = 0; m < platens_.size(); ++m) {
      const PlatenRow& p = platens_[m];
      const double ay[3] = {0.0, 1.0, p.rx};    // u_y at the contact point
      const double ax[3] = {1.0, 0.0, -p.ry};   // u_x at the contact point (sticking platens)
      const double ks = sticky_ ? p.k / M.law[M.block_material[std::size_t(p.block)]].kappa : 0.0;
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) v[platen_slots_[9 * m + 3 * a + c]] += p.k * ay[a] * ay[c] + ks * ax[a] * ax[c];
    }
    for (std::size_t k = 0; k < pins_.size(); ++k) v[pin_slots_[k]] += pins_[k].k;
    for (int z : zero_slots_) v[z] = 0.0;
    for (int d : unit_slots_) v[d] = 1.0;
    if (!full) return;
    *full = sym;
    double* w = full->valuePtr();
    for (std::size_t b = 0; b < nbond; ++b) {
      const double c = k_[b].slip_coupling(state[b]);  // sliding: F_s = sign(delta_s) mu k_n A delta_n
      if (broken[b] || c == 0.0) continue;
      const BondRows& r = rows_[b];
      const int* s = &slots_[36 * b];
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) w[s[6 * p + q]] += c * r.as[p] * r.an[q];
    }
    for (int z : zero_slots_) w[z] = 0.0;
    for (int d : unit_slots_) w[d] = 1.0;
  }

 private:
  int slot(int row, int col) const {
    const int* inner = pattern_.innerIndexPtr();
    const int* begin = inner + pattern_.outerIndexPtr()[col];
    const int* end = inner + pattern_.outerIndexPtr()[col + 1];
    return int(std::lower_bound(begin, end, row) - inner);
  }
  // The value slots of the fixed blocks' rows and columns (zeroed) and diagonals (one).
  void eliminate(const std::vector<int>& blocks) {
    fixed_dof_.assign(std::size_t(pattern_.rows()), 0);
    for (int b : blocks)
      for (int d = 0; d < 3; ++d) fixed_dof_[std::size_t(3 * b + d)] = 1;
    if (blocks.empty()) return;
    const int* outer = pattern_.outerIndexPtr();
    const int* inner = pattern_.innerIndexPtr();
    for (long col = 0; col < pattern_.cols(); ++col)
      for (int k = outer[col]; k < outer[col + 1]; ++k) {
        const bool on_fixed = fixed_dof_[std::size_t(col)] || fixed_dof_[std::size_t(inner[k])];
        if (!on_fixed) continue;
        (inner[k] == col ? unit_slots_ : zero_slots_).push_back(k);
      }
  }

  const Engine<2>& e_;
  std::vector<PlatenRow> platens_;
  bool sticky_ = false;
  std::vector<Pin> pins_;
  std::vector<BondRows> rows_;
  std::vector<BondStiffness> k_;
  std::vector<int> slots_, platen_slots_;
  std::vector<int> pin_slots_;
  std::vector<int> zero_slots_, unit_slots_;
  std::vector<std::uint8_t> fixed_dof_;
  SpMat pattern_;
};

// Weak springs for the rigid-body modes the supports leave free: the x translation between frictionless platens;
// without platens all three dofs of each anchor block. A load without resultant leaves them unloaded.
std::vector<Pin> rigid_body_pins(const Model<2>& M, const StaticSupports2& supports, const StaticOptions& options) {
  std::vector<Pin> pins;
  const auto& platens = supports.platen_rows;
  if (!platens.empty()) {
    double mean_diag = 0;
    for (const auto& p : platens) mean_diag += p.k;
    if (!supports.sticky_platens) pins.push_back({0, 1e-3 * mean_diag / double(platens.size())});
  } else {
    const std::size_t nbond = M.num_bonds();
    double k = 0, L2 = 0;
    for (std::size_t b = 0; b < nbond; ++b) k += M.frame.K[b], L2 += M.frame.L[b] * M.frame.L[b];
    k /= double(std::max<std::size_t>(nbond, 1)), L2 /= double(std::max<std::size_t>(nbond, 1));
    for (int b : options.anchors)
      pins.insert(pins.end(), {{3 * b, 1e-3 * k}, {3 * b + 1, 1e-3 * k}, {3 * b + 2, 1e-3 * k * L2}});
  }
  return pins;
}

// The right-hand side: the options' and the components' loads, and the top platen's closure delta (the overlap
// u_y(point) + delta of a top row stores k (u_y + delta)^2 / 2, which gives the load -k delta).
Eigen::VectorXd load_vector(std::size_t nb, const StaticSupports2& supports, const StaticOptions& options,
                            const std::vector<std::uint8_t>& fixed_dof, double delta) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(long(3 * nb));
  for (std::size_t k = 0; k < options.load.size(); ++k) f[long(k)] = options.load[k];
  for (std::size_t k = 0; k < supports.load.size(); ++k) f[long(k)] += supports.load[k];
  for (const auto& p : supports.platen_rows)
    if (p.top) {
      f[3 * p.block + 1] -= p.k * delta;
      f[3 * p.block + 2] -= p.k * delta * p.rx;
    }
  for (long d = 0; d < f.size(); ++d)
    if (fixed_dof[std::size_t(d)]) f[d] = 0.0;
  return f;
}

// The active-set iteration: each iteration solves K_full(states) u = f. The first state (every linear part closed
// and sticking) is symmetric: one sparse LDLT (AMD ordering) solves it exactly. Later states differ by the bonds
// that opened or slide, so BiCGSTAB preconditioned by that factorisation converges in a few iterations from the
// previous solution; if it does not, the current K_sym is factorised (same symbolic analysis) and BiCGSTAB retried,
// and sparse LU of K_full is the last resort. Fills r.linear_state and the iteration counts; returns u.
Eigen::VectorXd solve_active_set(const Engine<2>& e, const Stiffness& stiffness, const Eigen::VectorXd& f,
                                 const StaticOptions& options, StaticResult& r) {
  const auto& broken = e.state().broken;
  const std::size_t nbond = e.model().num_bonds();
  SpMat K_sym, K_full;
  Ldlt factor;
  factor.analyzePattern(stiffness.pattern());
  ParallelLdltSolve solves;  // the triangular solves on the threads the products have (planned when that changes)
  const auto threads = [&] { return options.threads ? std::max(options.threads->load(std::memory_order_relaxed), 1) : 1; };
  const auto singular = [] {
    return std::runtime_error("static solve: the bonded-block stiffness is singular (a block without bonds or "
                              "platen contact? check the mesh)");
  };
  auto factorise = [&]() {
    factor.factorize(K_sym);
    if (factor.info() != Eigen::Success) throw singular();
    solves.take_values(factor);
  };
  auto solver = [&]() -> const ParallelLdltSolve& {
    if (solves.threads() != threads()) solves.plan(factor, threads());
    return solves;
  };
  RowOperator K_rows(stiffness.pattern());
  Eigen::BiCGSTAB<RowOperator, FactorPreconditioner> krylov;
  krylov.setTolerance(options.krylov_tolerance);
  krylov.setMaxIterations(100);
  auto iterate = [&](Eigen::VectorXd& x) {
    K_rows.set(K_full, threads());
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
        if (lu.info() != Eigen::Success) throw singular();
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
      const std::uint8_t st = stiffness.k(b).linear_state(dn, ds);
      if (st == r.linear_state[b]) continue;
      if (flips[b] >= 2) {
        ++r.held_bonds;
        continue;
      }
      r.linear_state[b] = st, ++flips[b], ++changed;
    }
    if (changed <= settled) break;
  }
  return u;
}

// The platens' forces and shear of the solution u, and the apparent modulus.
void platen_results(const Engine<2>& e, const StaticSupports2& supports, const Eigen::VectorXd& u, double delta,
                    StaticResult& r) {
  const Model<2>& M = e.model();
  r.platen_fs.assign(M.num_blocks(), 0.0);
  for (const auto& p : supports.platen_rows) {
    const double uyp = u[3 * p.block + 1] + p.rx * u[3 * p.block + 2];
    if (p.top) r.top_force += p.k * (uyp + delta);
    else r.bottom_force += -p.k * uyp;
    if (supports.sticky_platens) {  // sticking platen: shear along t = perp(n), n = +-y into the platen
      const double uxp = u[3 * p.block] - p.ry * u[3 * p.block + 2];
      const double tx = p.top ? -1.0 : 1.0;
      r.platen_fs[p.block] += -(p.k / M.law[M.block_material[std::size_t(p.block)]].kappa) * uxp * tx;
    }
  }
  const double H = M.height, W = M.width, t = M.thickness;
  r.apparent_modulus = delta > 0.0 ? (r.top_force / (W * t)) / (delta / H) : 0.0;
}

// The bond forces of the solution u and the load factor of the first bond failure (all forces scale with the
// displacement): the parallel bond's own strength test (dem/laws/parallel_bond.hpp), solved for the load factor.
void bond_results(const Engine<2>& e, const Stiffness& stiffness, const Eigen::VectorXd& u, StaticResult& r) {
  const Model<2>& M = e.model();
  const auto& broken = e.state().broken;
  const std::size_t nbond = M.num_bonds();
  r.fn_b.resize(nbond), r.fs_b.resize(nbond), r.m_b.resize(nbond), r.fs_lin.assign(nbond, 0.0);
  r.fn_lin.assign(nbond, 0.0);
  r.first_break_factor = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < nbond; ++b) {
    if (broken[b]) continue;
    const BondRows& row = stiffness.rows(b);
    double dn = 0, ds = 0, dr = 0;
    for (int k = 0; k < 6; ++k) dn += row.an[k] * u[row.dof[k]], ds += row.as[k] * u[row.dof[k]], dr += row.ar[k] * u[row.dof[k]];
    const BondStiffness& k = stiffness.k(b);
    const double fn = -k.kbnA * dn, fs = -k.kbsA * ds, m = -k.kbnI * dr;
    r.fn_b[b] = fn, r.fs_b[b] = fs, r.m_b[b] = m;
    r.fs_lin[b] = k.linear_shear(r.linear_state[b], dn, ds);
    r.fn_lin[b] = r.linear_state[b] == StaticResult::open ? 0.0 : -k.knA * dn;
    BondStrength st = M.law[M.material[b]].bond.strength;
    st.sigma_c *= M.frame.strength_factor[b], st.cohesion *= M.frame.strength_factor[b];
    const double lam = st.first_break_factor(fn, fs, m, k.A, k.I, 0.5 * k.L);
    if (lam < r.first_break_factor) r.first_break_factor = lam, r.first_break_bond = int(b);
  }
}

}  // namespace

StaticResult solve_static(const Engine<2>& e, const StaticOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const Model<2>& M = e.model();
  const std::size_t nb = M.num_blocks(), nbond = M.num_bonds();
  const StaticSupports2 supports = supports_of(e, options.platens);
  const bool platens = !supports.platen_rows.empty();
  const double delta = platens ? options.platen_displacement : 0.0;
  if (options.platens && !platens)
    throw std::invalid_argument("static solve: no platen touches the specimen (no platens installed, or the mesh "
                                "has no edges on them: check the mesh boundary)");
  if (!options.load.empty() && options.load.size() != 3 * nb)
    throw std::invalid_argument("static solve: the load has " + std::to_string(options.load.size()) +
                                " entries; it needs 3 per block (fx, fy, moment)");
  if (!platens && options.anchors.empty() && supports.fixed.empty())
    throw std::invalid_argument("static solve: without platens the specimen needs an anchor block (rigid modes)");
  StaticResult r;
  r.dim = 2;
  r.platen_displacement = delta;
  r.dofs = 3 * nb;
  r.linear_state.assign(nbond, StaticResult::stick);
  const Stiffness stiffness(e, supports, rigid_body_pins(M, supports, options));
  const Eigen::VectorXd f = load_vector(nb, supports, options, stiffness.fixed_dof(), delta);
  const Eigen::VectorXd u = solve_active_set(e, stiffness, f, options, r);
  for (std::size_t b = 0; b < nbond; ++b) {
    if (e.state().broken[b]) continue;
    if (r.linear_state[b] == StaticResult::open) ++r.open_bonds;
    else if (r.linear_state[b] != StaticResult::stick) ++r.sliding_bonds;
  }
  r.u.assign(u.data(), u.data() + u.size());
  platen_results(e, supports, u, delta, r);
  bond_results(e, stiffness, u, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void apply_static_state(Engine<2>& e, const StaticResult& st, double factor, double velocity) {
  // Displacement per second per unit of the static field; a state not driven by the platens is put at rest.
  const double rate = st.platen_displacement > 0.0 ? velocity / st.platen_displacement : 0.0;
  const Model<2>& M = e.model();
  e.edit([&](ModelState<2>& s) {
    for (std::size_t b = 0; b < M.num_blocks(); ++b) {
      s.x[b] = M.x0[b] + factor * st.u[3 * b];
      s.y[b] = M.y0[b] + factor * st.u[3 * b + 1];
      s.theta[b] = factor * st.u[3 * b + 2];
      s.vx[b] = rate * st.u[3 * b], s.vy[b] = rate * st.u[3 * b + 1], s.omega[b] = rate * st.u[3 * b + 2];
    }
    for (std::size_t b = 0; b < M.num_bonds(); ++b) s.fs_lin[b] = factor * st.fs_lin[b];
    const double d = factor * st.platen_displacement;
    s.time = d > 0.0 ? d / velocity : 0.0;
  });
  for (BoundaryHooks<2>* h : e.hooks()) h->apply_static(M, e.state(), st, factor);
}

void apply_static_path(Engine<2>& e, const StaticResult& base, const StaticResult& inc, double lambda,
                       double velocity) {
  const StaticResult st = superpose(base, 1.0, inc, lambda);
  const double rate = velocity / inc.platen_displacement;  // the increment per second
  const Model<2>& M = e.model();
  e.edit([&](ModelState<2>& s) {
    for (std::size_t b = 0; b < M.num_blocks(); ++b) {
      s.x[b] = M.x0[b] + st.u[3 * b];
      s.y[b] = M.y0[b] + st.u[3 * b + 1];
      s.theta[b] = st.u[3 * b + 2];
      s.vx[b] = rate * inc.u[3 * b], s.vy[b] = rate * inc.u[3 * b + 1], s.omega[b] = rate * inc.u[3 * b + 2];
    }
    s.fs_lin = st.fs_lin;
    s.time = lambda * inc.platen_displacement / velocity;
  });
  for (BoundaryHooks<2>* h : e.hooks()) h->apply_static(M, e.state(), st, 1.0);
}

double stability_limit(const Engine<2>& e, int iterations, int threads_wanted) {
  const Model<2>& M = e.model();
  const std::size_t nb = M.num_blocks();
  std::vector<std::uint8_t> sticking(M.num_bonds(), StaticResult::stick);
  SpMat K;
  Stiffness(e, supports_of(e, true), {}).assemble(sticking, K, nullptr);
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

double first_break_along(const Engine<2>& e, const StaticResult& base, const StaticResult& inc, int* bond) {
  const Model<2>& M = e.model();
  const BondFrames& f = M.frame;
  double best = std::numeric_limits<double>::infinity();
  int which = -1;
  for (std::size_t b = 0; b < M.num_bonds(); ++b) {
    if (e.state().broken[b]) continue;
    const double lam = affine_break_factor(f.tension_limit[b], f.cohesion_A[b], f.tan_phi[b], f.beta_m[b], f.inv_L[b],
                                           M.law[M.material[b]].bond.moment_arm(), base.fn_b[b], base.fs_b[b],
                                           base.m_b[b], inc.fn_b[b], inc.fs_b[b], inc.m_b[b]);
    if (lam < best) best = lam, which = int(b);
  }
  if (bond) *bond = which;
  return best;
}

std::vector<double> break_factors_along(const Engine<2>& e, const StaticResult& base, const StaticResult& inc,
                                        bool mean_strength) {
  const Model<2>& M = e.model();
  const BondFrames& f = M.frame;
  const bool rest = base.empty();
  std::vector<double> factors(M.num_bonds(), std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b < M.num_bonds(); ++b) {
    if (e.state().broken[b]) continue;
    const double w = mean_strength ? f.strength_factor[b] : 1.0;
    factors[b] = affine_break_factor(f.tension_limit[b] / w, f.cohesion_A[b] / w, f.tan_phi[b], f.beta_m[b],
                                     f.inv_L[b], M.law[M.material[b]].bond.moment_arm(), rest ? 0.0 : base.fn_b[b],
                                     rest ? 0.0 : base.fs_b[b], rest ? 0.0 : base.m_b[b], inc.fn_b[b], inc.fs_b[b],
                                     inc.m_b[b]);
  }
  return factors;
}

StaticResult superpose(const StaticResult& a, double fa, const StaticResult& b, double fb) {
  StaticResult r = b;
  auto mix = [&](std::vector<double>& out, const std::vector<double>& x, const std::vector<double>& y) {
    out.resize(y.size());
    for (std::size_t k = 0; k < y.size(); ++k) out[k] = fa * x[k] + fb * y[k];
  };
  mix(r.u, a.u, b.u);
  mix(r.fn_b, a.fn_b, b.fn_b), mix(r.fs_b, a.fs_b, b.fs_b), mix(r.m_b, a.m_b, b.m_b);
  mix(r.fs_lin, a.fs_lin, b.fs_lin), mix(r.fn_lin, a.fn_lin, b.fn_lin), mix(r.platen_fs, a.platen_fs, b.platen_fs);
  r.top_force = fa * a.top_force + fb * b.top_force;
  r.bottom_force = fa * a.bottom_force + fb * b.bottom_force;
  r.platen_displacement = fa * a.platen_displacement + fb * b.platen_displacement;
  r.first_break_factor = std::numeric_limits<double>::infinity();
  r.first_break_bond = -1;
  return r;
}

}  // namespace rbdem
