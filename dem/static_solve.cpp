// Static elastic solve and stability limit. See static_solve.hpp.
#include "dem/static_solve.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <fmt/format.h>

namespace rbdem {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Adds k (a . u)^2 / 2 for a linear functional a over up to 6 dofs.
void add_rank_one(Triplets& T, const int* dof, const double* a, int n, double k) {
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q)
      if (a[p] != 0.0 && a[q] != 0.0) T.emplace_back(dof[p], dof[q], k * a[p] * a[q]);
}

struct BondRows {
  int dof[6];
  double an[6], as[6], ar[6];  // normal opening, shear, relative rotation as functionals of the dofs
};

// Linearised kinematics of bond b at the reference configuration (the engine's bond kernel, linearised):
// delta = u_j + theta_j z x r_j - u_i - theta_i z x r_i, with r the lever arms to the edge midpoint.
BondRows bond_rows(const Engine& e, std::size_t b) {
  const auto& D = e.bonds;
  const int i = D.i[b], j = D.j[b];
  const BondFrame& f = D.frame[b];
  BondRows r{{3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2}, {}, {}, {}};
  const double nx = f.n0x, ny = f.n0y, tx = -ny, ty = nx;
  // z x r = (-r_y, r_x)
  const double dx[6] = {-1, 0, f.riy, 1, 0, -f.rjy};
  const double dy[6] = {0, -1, -f.rix, 0, 1, f.rjx};
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
  double rx, ry; // contact point (edge midpoint) relative to the centroid
};

std::vector<PlatenRow> platen_rows(const Engine& e) {
  std::vector<PlatenRow> rows;
  if (!e.has_platens()) return rows;
  const Topology& topo = e.topology();
  const auto& E = topo.boundary;
  for (std::size_t k = 0; k < E.size(); ++k) {
    if (E.side[k] != Side::top && E.side[k] != Side::bottom) continue;
    const int b = E.block[k];
    const auto& shape = topo.blocks.shape[b];
    // the edge's end points relative to the centroid: find the vertices on the platen line
    double mx = 0, my = 0;
    int found = 0;
    const double y_line = E.side[k] == Side::top ? topo.ymax : topo.ymin;
    for (int v = 0; v < 3; ++v)
      if (std::abs(topo.blocks.cy[b] + shape[2 * v + 1] - y_line) < 1e-9 * topo.height())
        mx += shape[2 * v], my += shape[2 * v + 1], ++found;
    if (found != 2) continue;
    rows.push_back({b, E.side[k] == Side::top, e.platen_stiffness(b) * e.thickness() * E.length[k], 0.5 * mx, 0.5 * my});
  }
  return rows;
}

// Adds k a b^T (a non-symmetric rank one term: force along a driven by the displacement measure b).
void add_outer(Triplets& T, const int* dof, const double* a, const double* b, int n, double k) {
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q)
      if (a[p] != 0.0 && b[q] != 0.0) T.emplace_back(dof[p], dof[q], k * a[p] * b[q]);
}

Eigen::SparseMatrix<double> assemble(const Engine& e, const std::vector<std::uint8_t>& state,
                                     const std::vector<PlatenRow>& platens, double pin) {
  const auto& D = e.bonds;
  const std::size_t n = 3 * e.blocks.size();
  Triplets T;
  T.reserve(D.i.size() * 144 + platens.size() * 18 + 1);
  for (std::size_t b = 0; b < D.i.size(); ++b) {
    if (D.broken[b]) continue;
    const BondRows r = bond_rows(e, b);
    const BondStiffness k = e.stiffness(int(b));
    const std::uint8_t st = state[b];
    add_rank_one(T, r.dof, r.an, 6, k.kbnA + (st != StaticResult::open ? k.knA : 0.0));
    add_rank_one(T, r.dof, r.as, 6, k.kbsA + (st == StaticResult::stick ? k.ksA : 0.0));
    add_rank_one(T, r.dof, r.ar, 6, k.kbnI);
    if (st == StaticResult::slip_positive || st == StaticResult::slip_negative) {
      // sliding: F_s = sign(delta_s) mu k_n A delta_n, a shear force driven by the normal closure
      const double sign = st == StaticResult::slip_positive ? 1.0 : -1.0;
      add_outer(T, r.dof, r.as, r.an, 6, -sign * k.mu * k.knA);
    }
  }
  const bool sticky = e.platen_friction() > 0.0;
  for (const auto& p : platens) {
    const int dof[3] = {3 * p.block, 3 * p.block + 1, 3 * p.block + 2};
    const double ay[3] = {0.0, 1.0, p.rx};   // u_y at the contact point
    add_rank_one(T, dof, ay, 3, p.k);
    if (sticky) {
      const double ax[3] = {1.0, 0.0, -p.ry};  // u_x at the contact point
      add_rank_one(T, dof, ax, 3, p.k / e.kappa(BondKind::rock));
    }
  }
  if (pin > 0) T.emplace_back(0, 0, pin);  // removes the free x translation of frictionless platens
  Eigen::SparseMatrix<double> K{long(n), long(n)};
  K.setFromTriplets(T.begin(), T.end());
  return K;
}

}  // namespace

StaticResult solve_static(const Engine& e, const StaticOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& D = e.bonds;
  const std::size_t nb = e.blocks.size(), nbond = D.size();
  const double delta = options.platen_displacement;
  const auto platens = platen_rows(e);
  if (platens.empty())
    throw std::invalid_argument("static solve: the specimen has no edges on the platens (check the mesh boundary)");
  StaticResult r;
  r.platen_displacement = delta;
  r.dofs = 3 * nb;
  r.linear_state.assign(nbond, StaticResult::stick);

  double mean_diag = 0;
  for (const auto& p : platens) mean_diag += p.k;
  const double pin = e.platen_friction() > 0.0 ? 0.0 : 1e-3 * mean_diag / double(platens.size());

  Eigen::VectorXd f = Eigen::VectorXd::Zero(long(3 * nb));
  for (const auto& p : platens)
    if (p.top) {  // overlap = u_y(point) + delta: energy k (u_y + delta)^2 / 2 gives the load -k delta
      f[3 * p.block + 1] -= p.k * delta;
      f[3 * p.block + 2] -= p.k * delta * p.rx;
    }
  Eigen::VectorXd u;
  // Bonds whose state flips back and forth between iterations are few and near a state boundary, where both
  // states give nearly the same forces; stop when at most this many change.
  const std::size_t settled = nbond / 10000;
  for (int it = 0; it < options.max_iterations; ++it) {
    r.active_set_iterations = it + 1;
    const auto K = assemble(e, r.linear_state, platens, pin);
    Eigen::SparseLU<Eigen::SparseMatrix<double>> solver;
    solver.analyzePattern(K);
    solver.factorize(K);
    if (solver.info() != Eigen::Success)
      throw std::runtime_error("static solve: the bonded-block stiffness is singular (a block without bonds or "
                               "platen contact? check the mesh)");
    u = solver.solve(f);
    if (options.linear_parts_always_closed) break;
    std::size_t changed = 0;
    for (std::size_t b = 0; b < nbond; ++b) {
      if (D.broken[b]) continue;
      const BondRows row = bond_rows(e, b);
      double dn = 0, ds = 0;
      for (int k = 0; k < 6; ++k) dn += row.an[k] * u[row.dof[k]], ds += row.as[k] * u[row.dof[k]];
      std::uint8_t st = StaticResult::open;
      if (dn < 0.0) {
        const BondStiffness k = e.stiffness(int(b));
        st = std::abs(k.ksA * ds) <= k.mu * (-k.knA * dn)
                 ? StaticResult::stick
                 : (ds > 0 ? StaticResult::slip_positive : StaticResult::slip_negative);
      }
      if (st != r.linear_state[b]) r.linear_state[b] = st, ++changed;
    }
    if (changed <= settled) break;
  }
  for (std::size_t b = 0; b < nbond; ++b) {
    if (D.broken[b]) continue;
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
      r.platen_fs[p.block] += -(p.k / e.kappa(BondKind::rock)) * uxp * tx;
    }
  }
  const double H = e.specimen_height(), W = e.specimen_width(), t = e.thickness();
  r.apparent_modulus = (r.top_force / (W * t)) / (delta / H);

  // Bond forces and the load factor of the first bond failure (all forces scale with the displacement).
  r.fn_b.resize(nbond), r.fs_b.resize(nbond), r.m_b.resize(nbond), r.fs_lin.assign(nbond, 0.0);
  r.first_break_factor = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < nbond; ++b) {
    if (D.broken[b]) continue;
    const BondRows row = bond_rows(e, b);
    double dn = 0, ds = 0, dr = 0;
    for (int k = 0; k < 6; ++k) dn += row.an[k] * u[row.dof[k]], ds += row.as[k] * u[row.dof[k]], dr += row.ar[k] * u[row.dof[k]];
    const BondStiffness k = e.stiffness(int(b));
    const double fn = -k.kbnA * dn, fs = -k.kbsA * ds, m = -k.kbnI * dr;
    r.fn_b[b] = fn, r.fs_b[b] = fs, r.m_b[b] = m;
    const std::uint8_t ls = r.linear_state[b];
    if (ls == StaticResult::stick) r.fs_lin[b] = -k.ksA * ds;
    else if (ls != StaticResult::open) r.fs_lin[b] = (ls == StaticResult::slip_positive ? -1.0 : 1.0) * k.mu * (-k.knA * dn);
    const BondStrength& st = e.strength(D.kind[b]);
    const double A = k.A, I = k.I, R = 0.5 * k.L;
    const double sn = -fn / A, sigma = sn + st.beta_m * std::abs(m) * R / I, tau = std::abs(fs) / A;
    double lam = std::numeric_limits<double>::infinity();
    if (sigma > 0) lam = std::min(lam, st.sigma_c / sigma);
    // shear: lam tau = c - min(lam sn, sigma_c) tan(phi)
    const double den = tau + sn * st.tan_phi;
    if (den > 0) {
      const double l1 = st.cohesion / den;
      if (l1 * sn <= st.sigma_c) lam = std::min(lam, l1);
    }
    if (tau > 0 && st.cohesion - st.sigma_c * st.tan_phi > 0) {
      const double l2 = (st.cohesion - st.sigma_c * st.tan_phi) / tau;
      if (l2 * sn > st.sigma_c) lam = std::min(lam, l2);
    }
    if (lam < r.first_break_factor) r.first_break_factor = lam, r.first_break_bond = int(b);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void apply_static_state(Engine& e, const StaticResult& st, double factor, double velocity) {
  const double rate = velocity / st.platen_displacement;  // displacement per second per unit of the static field
  for (std::size_t b = 0; b < e.blocks.size(); ++b) {
    BlockState& s = e.blocks.state[b];
    s.x = e.blocks.x0[b] + factor * st.ux[b];
    s.y = e.blocks.y0[b] + factor * st.uy[b];
    s.theta = factor * st.rotation[b];
    s.vx = rate * st.ux[b], s.vy = rate * st.uy[b], s.omega = rate * st.rotation[b];
  }
  for (std::size_t b = 0; b < e.bonds.size(); ++b) e.bonds.fs_lin[b] = factor * st.fs_lin[b];
  for (std::size_t b = 0; b < e.blocks.size(); ++b)
    if (st.platen_fs[b] != 0.0) e.set_platen_shear(int(b), factor * st.platen_fs[b]);
  const double d = factor * st.platen_displacement;
  e.set_platen_displacement(d);
  e.set_time(d / velocity);
  e.refresh();
}

double stability_limit(const Engine& e, int iterations) {
  const std::size_t nb = e.blocks.size();
  std::vector<std::uint8_t> sticking(e.bonds.size(), StaticResult::stick);
  const auto K = assemble(e, sticking, platen_rows(e), 0.0);
  Eigen::VectorXd inv_sqrt_m(long(3 * nb));
  for (std::size_t b = 0; b < nb; ++b) {
    inv_sqrt_m[3 * b] = inv_sqrt_m[3 * b + 1] = 1.0 / std::sqrt(e.blocks.mass[b]);
    inv_sqrt_m[3 * b + 2] = 1.0 / std::sqrt(e.blocks.inertia[b]);
  }
  // Power iteration on M^-1/2 K M^-1/2 from a deterministic rough start.
  Eigen::VectorXd v(long(3 * nb));
  for (long k = 0; k < v.size(); ++k) v[k] = std::sin(12.9898 * double(k) + 1.0);
  v.normalize();
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    Eigen::VectorXd w = inv_sqrt_m.cwiseProduct(K * inv_sqrt_m.cwiseProduct(v));
    lambda = v.dot(w);
    const double norm = w.norm();
    if (!(norm > 0)) break;
    v = w / norm;
  }
  return 2.0 / std::sqrt(lambda);
}

}  // namespace rbdem
