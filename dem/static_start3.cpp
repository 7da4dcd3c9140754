// The static start of the 3D model. See static_start3.hpp.
#include "dem/static_start3.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/SparseCore>

namespace rbdem {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// The rows a platen spring acts on, as functionals of the block's six dofs: the normal u_z + (phi x r)_z and the
// slips u_x + (phi x r)_x, u_y + (phi x r)_y.
std::array<double, 6> normal_row(Vec3 r) { return {0.0, 0.0, 1.0, r.y, -r.x, 0.0}; }
std::array<double, 6> slip_row(Vec3 r, int axis) {
  if (axis == 0) return {1.0, 0.0, 0.0, 0.0, r.z, -r.y};
  return {0.0, 1.0, 0.0, -r.z, 0.0, r.x};
}
double apply_row(const std::array<double, 6>& row, const double* u) {
  double s = 0;
  for (int p = 0; p < 6; ++p) s += row[std::size_t(p)] * u[p];
  return s;
}

std::vector<PlatenRow3> platen_rows(const Engine<3>& e) {
  std::vector<PlatenRow3> rows;
  for (const BoundaryHooks<3>* h : e.hooks()) h->static_rows(e.model(), rows);
  return rows;
}

// The relative motion of bond b's pair in its face frame for the small displacements u (6 per block).
FaceMotion motion_of(const Model<3>& m, std::size_t b, const std::vector<double>& u) {
  const stages::FaceBondFrame& f = m.frame[b];
  const double* ui = &u[6 * std::size_t(m.bi[b])];
  const double* uj = &u[6 * std::size_t(m.bj[b])];
  const Vec3 pi{ui[3], ui[4], ui[5]}, pj{uj[3], uj[4], uj[5]};
  const Vec3 g = Vec3{uj[0], uj[1], uj[2]} + cross(pj, f.rj) - Vec3{ui[0], ui[1], ui[2]} - cross(pi, f.ri);
  const Vec3 d = f.axes * g, t = f.axes * (pj - pi);
  return {d.x, d.y, d.z, t.x, t.y, t.z};
}

// The stiffness of the bonds (linear parts closed where `closed`) and the platen springs, over the dofs `map`
// (-1: held), as triplets. `bound`: the stiffness that bounds the explicit law's from above (the stability limit):
// a linear part that closes over part of its face carries its force at the centroid of that part, so it can add as
// much bending and twist stiffness as the parallel bond has; a platen contact on the overlap volume adds its
// rotational stiffness likewise.
void add_stiffness(const Model<3>& m, const std::vector<std::uint8_t>& closed, const std::vector<PlatenRow3>& rows,
                   const std::vector<int>& map, std::vector<Eigen::Triplet<double>>& T, bool bound = false) {
  auto add = [&](std::size_t gp, std::size_t gq, double v) {
    const int p = map[gp], q = map[gq];
    if (p >= 0 && q >= 0 && v != 0.0) T.emplace_back(p, q, v);
  };
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    stages::FaceBondFrame f = m.frame[b];
    if (bound) f.k = {2 * f.k.kn, 2 * f.k.ks, 2 * f.k.kb1, 2 * f.k.kb2, 2 * f.k.kt};
    const FaceBondMatrix K = face_bond_stiffness(f, !bound && closed[b] != 0);
    const std::size_t dof[2] = {6 * std::size_t(m.bi[b]), 6 * std::size_t(m.bj[b])};
    for (std::size_t p = 0; p < 12; ++p)
      for (std::size_t q = 0; q < 12; ++q) add(dof[p / 6] + p % 6, dof[q / 6] + q % 6, K[12 * p + q]);
  }
  for (const PlatenRow3& r : rows) {
    const std::size_t base = 6 * std::size_t(r.block);
    auto spring = [&](double k, const std::array<double, 6>& row) {
      for (std::size_t p = 0; p < 6; ++p)
        for (std::size_t q = 0; q < 6; ++q) add(base + p, base + q, k * row[p] * row[q]);
    };
    spring(r.kn, normal_row(r.r));
    if (r.ks > 0) spring(r.ks, slip_row(r.r, 0)), spring(r.ks, slip_row(r.r, 1));
    if (bound) spring(r.kb, {0, 0, 0, 1, 0, 0}), spring(r.kb, {0, 0, 0, 0, 1, 0});
  }
}

// The dofs left after the rigid constraints of frictionless platens (static_start3.hpp); all with sticking ones.
std::vector<int> free_dofs(const Model<3>& m, const std::vector<PlatenRow3>& rows) {
  std::vector<int> map(6 * m.num_blocks(), 0);
  const bool sticky = std::any_of(rows.begin(), rows.end(), [](const PlatenRow3& r) { return r.ks > 0; });
  if (!sticky) {
    int first = -1, far = -1;
    for (const PlatenRow3& r : rows)
      if (!r.top && (first < 0 || r.block < first)) first = r.block;
    if (first < 0) throw std::invalid_argument("the static solve needs the platens: install them first");
    for (const PlatenRow3& r : rows)
      if (!r.top && (far < 0 || std::abs(m.x0[std::size_t(r.block)].x - m.x0[std::size_t(first)].x) >
                                    std::abs(m.x0[std::size_t(far)].x - m.x0[std::size_t(first)].x)))
        far = r.block;
    map[6 * std::size_t(first)] = map[6 * std::size_t(first) + 1] = map[6 * std::size_t(far) + 1] = -1;
  }
  int next = 0;
  for (int& k : map) k = k < 0 ? -1 : next++;
  return map;
}

}  // namespace

StaticResult solve_static(const Engine<3>& e, const StaticOptions& o, Static3Solver solver) {
  const auto t0 = std::chrono::steady_clock::now();
  const Model<3>& m = e.model();
  const std::vector<PlatenRow3> rows = o.platens ? platen_rows(e) : std::vector<PlatenRow3>{};
  if (rows.empty()) throw std::invalid_argument("the 3D static solve needs the platens (a disc start is not built)");
  const std::vector<int> map = free_dofs(m, rows);
  const long n = long(std::count_if(map.begin(), map.end(), [](int k) { return k >= 0; }));
  const double delta = o.platen_displacement;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  for (const PlatenRow3& r : rows) {
    if (!r.top) continue;
    const auto row = normal_row(r.r);
    for (std::size_t p = 0; p < 6; ++p)
      if (const int gp = map[6 * std::size_t(r.block) + p]; gp >= 0) f[gp] -= r.kn * delta * row[p];
  }
  for (std::size_t k = 0; k < o.load.size() && k < map.size(); ++k)
    if (map[k] >= 0) f[map[k]] += o.load[k];
  StaticResult r;
  r.dim = 3, r.platen_displacement = delta;
  std::vector<std::uint8_t> closed(m.num_bonds(), 1), changes(m.num_bonds(), 0);
  const int max_it = o.linear_parts_always_closed ? 1 : std::max(o.max_iterations, 1);
  SpdSolver3 spd(solver);
  for (int it = 0; it < max_it; ++it) {
    std::vector<Eigen::Triplet<double>> T;
    add_stiffness(m, closed, rows, map, T);
    SpMat K(n, n);
    K.setFromTriplets(T.begin(), T.end());
    // The first stiffness (every linear part closed) is factorised; the active sets after it lie within a factor 2
    // of it (an opened linear part takes away its k_n A and k_s A, no more than the parallel bond beside it keeps)
    // and are solved by CG preconditioned with that factor (SpdSolver3::update).
    if (it == 0) spd.factor(K);
    else spd.update(K);
    const Eigen::VectorXd x = spd.solve(f);
    r.u.assign(map.size(), 0.0);
    for (std::size_t k = 0; k < map.size(); ++k)
      if (map[k] >= 0) r.u[k] = x[map[k]];
    ++r.active_set_iterations;
    // A linear part that changed twice is held (an active-set cycle near the open/closed boundary, where its force
    // is small either way).
    std::size_t changed = 0;
    for (std::size_t b = 0; b < m.num_bonds(); ++b) {
      const std::uint8_t now = motion_of(m, b, r.u).dn < 0 ? 1 : 0;
      if (o.linear_parts_always_closed || now == closed[b]) continue;
      if (changes[b] >= 2) {
        ++r.held_bonds;
        continue;
      }
      closed[b] = now, ++changes[b], ++changed;
    }
    if (changed == 0) break;
  }
  r.krylov_iterations = spd.iterations();
  r.linear_state.resize(m.num_bonds());
  r.fn_lin.resize(m.num_bonds());
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    r.linear_state[b] = closed[b] ? StaticResult::stick : StaticResult::open;
    r.fn_lin[b] = closed[b] ? -m.frame[b].k.kn * motion_of(m, b, r.u).dn : 0.0;
    r.open_bonds += closed[b] ? 0 : 1;
  }
  for (const PlatenRow3& row : rows) {
    const double uz = apply_row(normal_row(row.r), &r.u[6 * std::size_t(row.block)]);
    (row.top ? r.top_force : r.bottom_force) += row.kn * (row.top ? uz + delta : -uz);
  }
  const double H = m.hi.z - m.lo.z;
  r.apparent_modulus = delta > 0 ? 0.5 * (r.top_force + r.bottom_force) / m.loaded_area / (delta / H) : 0.0;
  r.dofs = std::size_t(n);
  r.first_break_factor = first_break_along(e, StaticResult{}, r, &r.first_break_bond);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

// The smallest lambda >= 0 at which g(lambda) >= 0, for g the larger of the tensile and shear margins of a bond on an
// affine path: each is convex in lambda on either side of the point where the normal stress reaches sigma_c (the
// cap of the shear limit), so the first crossing lies between the last sample below zero and the first one above on
// a fine grid, and bisection finds it. +inf when g stays below zero up to 1e12.
template <class G>
double first_root(const G& g) {
  if (g(0.0) >= 0) return 0.0;
  double hi = 1.0;
  while (g(hi) < 0) {
    hi *= 2.0;
    if (hi > 1e12) return std::numeric_limits<double>::infinity();
  }
  double lo = 0.0;
  const int n = 64;
  for (int k = 1; k <= n; ++k) {
    const double x = hi * double(k) / double(n);
    if (g(x) >= 0) {
      hi = x;
      break;
    }
    lo = x;
  }
  for (int it = 0; it < 60 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) >= 0 ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace

double first_break_along(const Engine<3>& e, const StaticResult& base, const StaticResult& st, int* bond) {
  const Model<3>& m = e.model();
  double best = std::numeric_limits<double>::infinity();
  int which = -1;
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    if (e.state().broken[b]) continue;
    const FaceBond law = m.bond_law(b);
    const FaceSection& sec = m.frame[b].section;
    const FaceForces f1 = FaceBond::forces(m.frame[b].k, motion_of(m, b, st.u));
    double lam = std::numeric_limits<double>::infinity();
    if (base.empty()) {
      // From rest the loads are homogeneous in lambda: tension lambda T <= sigma_c A; shear lambda S <= c A -
      // min(lambda N, sigma_c A) tan(phi) with N = -F_n the tensile normal force at lambda = 1; solved exactly.
      const BondLoad q = law.load(sec, f1);
      const double sA = law.strength.sigma_c * sec.A, cA = law.strength.cohesion * sec.A, tp = law.strength.tan_phi;
      const double N = -f1.fn;
      if (q.tension > 0) lam = sA / q.tension;
      const double den = q.shear + (tp > 0 ? N * tp : 0.0);
      if (den > 0) {
        const double l1 = cA / den;
        if (!(tp > 0) || l1 * N <= sA) lam = std::min(lam, l1);
        else if (q.shear > 0) lam = std::min(lam, (cA - sA * tp) / q.shear);
      }
    } else {
      const FaceForces f0 = FaceBond::forces(m.frame[b].k, motion_of(m, b, base.u));
      lam = first_root([&](double x) {
        const FaceForces f{f0.fs1 + x * f1.fs1, f0.fs2 + x * f1.fs2, f0.fn + x * f1.fn,
                           f0.m1 + x * f1.m1,   f0.m2 + x * f1.m2,   f0.mt + x * f1.mt};
        const BondLoad q = law.load(sec, f);
        return std::max(q.tension - q.tension_limit, q.shear - q.shear_limit);
      });
    }
    if (lam < best) best = lam, which = int(b);
  }
  if (bond) *bond = which;
  return best;
}

void apply_static(Engine<3>& e, const StaticResult& base, const StaticResult& st, double lambda, double velocity) {
  const Model<3>& m = e.model();
  const StaticResult total = superpose(base.empty() ? st : base, base.empty() ? 0.0 : 1.0, st, lambda);
  const double rate = st.platen_displacement > 0 ? velocity / st.platen_displacement : 0.0;
  e.edit([&](ModelState<3>& s) {
    for (std::size_t b = 0; b < m.num_blocks(); ++b) {
      const double* u = &total.u[6 * b];
      const double* du = &st.u[6 * b];
      s.x[b] = m.x0[b].x + u[0], s.y[b] = m.x0[b].y + u[1], s.z[b] = m.x0[b].z + u[2];
      const Quat q = from_rotation_vector({u[3], u[4], u[5]});
      s.qw[b] = q.w, s.qx[b] = q.x, s.qy[b] = q.y, s.qz[b] = q.z;
      s.vx[b] = rate * du[0], s.vy[b] = rate * du[1], s.vz[b] = rate * du[2];
      s.wx[b] = rate * du[3], s.wy[b] = rate * du[4], s.wz[b] = rate * du[5];
    }
    for (std::size_t b = 0; b < m.num_bonds(); ++b) {
      const FaceMotion d = motion_of(m, b, total.u);
      const bool closed = st.linear_state.empty() || st.linear_state[b] != StaticResult::open;
      s.fs1[b] = closed ? -m.frame[b].k.ks * d.d1 : 0.0;
      s.fs2[b] = closed ? -m.frame[b].k.ks * d.d2 : 0.0;
    }
    s.time = velocity > 0 ? lambda * st.platen_displacement / velocity : 0.0;
  });
  for (BoundaryHooks<3>* h : e.hooks()) h->apply_static(m, total, 1.0);
}

double stability_limit(const Engine<3>& e, int iterations) {
  const Model<3>& m = e.model();
  const std::size_t nb = m.num_blocks(), n = 6 * nb;
  std::vector<int> map(n);
  for (std::size_t k = 0; k < n; ++k) map[k] = int(k);
  std::vector<Eigen::Triplet<double>> T;
  std::vector<PlatenRow3> rows = platen_rows(e);
  for (PlatenRow3& r : rows) r.ks = r.kn;  // a sliding or sticking platen: its shear stiffness bounded by k_n
  add_stiffness(m, std::vector<std::uint8_t>(m.num_bonds(), 1), rows, map, T, true);
  SpMat K(static_cast<long>(n), static_cast<long>(n));
  K.setFromTriplets(T.begin(), T.end());
  // Power iteration on M^-1/2 K M^-1/2 (symmetric: the Rayleigh quotient converges to lambda_max from below) from
  // a deterministic rough start. M^-1/2 is 1 / sqrt(m) on the translations and R diag(1 / sqrt(I_k)) R^T on the
  // rotations, R the block's principal axes at rest.
  auto inverse_sqrt_mass = [&](Eigen::VectorXd& y) {
    for (std::size_t b = 0; b < nb; ++b) {
      const RigidBody3& body = m.body[b];
      const double s = 1.0 / std::sqrt(body.mass);
      for (std::size_t k = 0; k < 3; ++k) y[long(6 * b + k)] *= s;
      const Vec3 a = rotate_back(body.axes, {y[long(6 * b + 3)], y[long(6 * b + 4)], y[long(6 * b + 5)]});
      const Vec3 w = rotate(body.axes, {a.x / std::sqrt(body.moments.x), a.y / std::sqrt(body.moments.y),
                                        a.z / std::sqrt(body.moments.z)});
      y[long(6 * b + 3)] = w.x, y[long(6 * b + 4)] = w.y, y[long(6 * b + 5)] = w.z;
    }
  };
  Eigen::VectorXd v(static_cast<long>(n));
  for (long k = 0; k < long(n); ++k) v[k] = std::sin(12.9898 * double(k) + 1.0);
  v.normalize();
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    Eigen::VectorXd y = v;
    inverse_sqrt_mass(y);
    Eigen::VectorXd w = K * y;
    inverse_sqrt_mass(w);
    lambda = v.dot(w);
    const double norm = w.norm();
    if (!(norm > 0)) break;
    v = w / norm;
  }
  return lambda > 0 ? 2.0 / std::sqrt(lambda) : std::numeric_limits<double>::infinity();
}

}  // namespace rbdem
