// The integrator: per-block gather of the bond slots (fixed CSR order) and the contact and boundary forces,
// Cundall's local damping, and the central difference update of x, y, theta (docs/theory.md, section 8). It sees
// forces and masses, never a law. See stages.hpp.
#include <cmath>

#include <fmt/format.h>

#include "dem/engine.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

// Adds the slot of one CSR entry (2 bond + 1 if the block is the bond's j) to a block's force and moment. Without
// branches: a block's role in its bonds follows no pattern, so an `if` mispredicts, and x + (-1) a is x - a exactly.
inline void add_slot(int e, const Workspace& w, double& fx, double& fy, double& m) {
  const Workspace::Slot& s = w.slot[std::size_t(e >> 1)];
  const bool is_j = e & 1;
  const double sign = is_j ? 1.0 : -1.0;
  fx += sign * s.fx, fy += sign * s.fy, m += is_j ? s.mj : s.mi;
}

}  // namespace

void update_rotations(const ModelState& s, Workspace& w, int threads) {
  const int n = int(s.num_blocks());
  w.cos_t.resize(std::size_t(n)), w.sin_t.resize(std::size_t(n));
  const double* theta = s.theta.data();
  double *c = w.cos_t.data(), *sn = w.sin_t.data();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int b = 0; b < n; ++b) {
    // Blocks rotate by well under 0.01 rad until they break free; there the Taylor series are exact to round-off
    // (the first omitted terms are below 3e-18 relative) and far cheaper than sin and cos.
    const double q = theta[b];
    if (std::abs(q) < 0.01) {
      const double q2 = q * q;
      sn[b] = q * (1.0 - q2 * (1.0 / 6.0 - q2 * (1.0 / 120.0)));
      c[b] = 1.0 - q2 * (0.5 - q2 * (1.0 / 24.0 - q2 * (1.0 / 720.0)));
    } else {
      c[b] = std::cos(q);
      sn[b] = std::sin(q);
    }
  }
}

void integrate(const Model& m, ModelState& s, Workspace& w, double damping, int threads) {
  const int* offset = m.csr_offset.data();
  const int* entry = m.csr_entry.data();
  const int n = int(m.num_blocks());
  const double dt = s.dt, alpha = damping;
  double e_damp = 0.0;
  bool finite = true;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : e_damp) reduction(&& : finite)
  for (int b = 0; b < n; ++b) {
    double fx = w.cfx[b] + w.ext_fx[b], fy = w.cfy[b] + w.ext_fy[b], mz = w.cm[b] + w.ext_m[b];
    for (int o = offset[b]; o < offset[b + 1]; ++o) add_slot(entry[o], w, fx, fy, mz);
    s.fx[b] = fx, s.fy[b] = fy, s.moment[b] = mz;
    if (m.fixed[b]) continue;
    double &vx = s.vx[b], &vy = s.vy[b], &om = s.omega[b];
    // Cundall local damping: F_d = -alpha |F| sign(v), per degree of freedom.
    const double dfx = -alpha * std::abs(fx) * double((vx > 0) - (vx < 0));
    const double dfy = -alpha * std::abs(fy) * double((vy > 0) - (vy < 0));
    const double dm = -alpha * std::abs(mz) * double((om > 0) - (om < 0));
    e_damp -= (dfx * vx + dfy * vy + dm * om) * dt;
    const double inv_m = m.inv_mass[b];
    vx += dt * (fx + dfx) * inv_m;
    vy += dt * (fy + dfy) * inv_m;
    om += dt * (mz + dm) / m.inertia[b];
    s.x[b] += dt * vx;
    s.y[b] += dt * vy;
    s.theta[b] += dt * om;
    finite = finite && std::isfinite(s.x[b]) && std::isfinite(s.y[b]) && std::isfinite(s.theta[b]);
  }
  s.e_damping += e_damp;
  if (!finite)
    throw InstabilityError(fmt::format(
        "the run diverged at step {} (t = {:.4g} s): positions are no longer finite. The time step {:.4g} s is too "
        "large for this scene; lower numerics.dt or numerics.dt_safety",
        s.steps, s.time, s.dt));
}

void gather_forces(const Model& m, const ModelState& s, const Workspace& w, std::vector<double>& fx,
                   std::vector<double>& fy, std::vector<double>& moment) {
  (void)s;
  const std::size_t n = m.num_blocks();
  fx.resize(n), fy.resize(n), moment.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    double f_x = w.cfx[b] + w.ext_fx[b], f_y = w.cfy[b] + w.ext_fy[b], mz = w.cm[b] + w.ext_m[b];
    for (int o = m.csr_offset[b]; o < m.csr_offset[b + 1]; ++o) add_slot(m.csr_entry[o], w, f_x, f_y, mz);
    fx[b] = f_x, fy[b] = f_y, moment[b] = mz;
  }
}

}  // namespace rbdem::stages
