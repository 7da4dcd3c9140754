// One bond's kinematics and forces: the body of the bond stage (bonds.cpp), also used by the bond events and the
// diagnostics (Engine::bond_forces). It reads the two blocks' kinematics and the bond's frame and calls the laws:
// ParallelBond::forces for the parallel bond, LinearContact on the bond's edge for the linear part (dem/laws/).
//
// The body has no branches (every case is computed and one selected) and reads plain arrays, so the bond stage's
// loop vectorises (`#pragma omp simd`); the scalar callers run the very same code, lane by lane, and get the very
// same numbers.
#pragma once

#include <cmath>

#include "dem/model.hpp"
#include "dem/stages/stages.hpp"
#include "dem/state.hpp"

namespace rbdem::stages {

// The forces of one bond in its co-rotated frame and what the slot receives.
struct BondEval {
  double fnb, fsb, mb;    // parallel bond, undamaged (N, N, N m)
  double fnl, fsl;        // linear part (N)
  double fx, fy, mi, mj;  // the slot: force on j, moments on i and j (damage applied)
  double px, py;          // bond point (world, m)
};

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// One block's kinematics as a bond reads them: position, rotation, velocities, and cos and sin of the rotation.
struct BlockKin {
  double x, y, theta, vx, vy, omega, c, s;
};

// What a bond's evaluation reads: the model's bond arrays, and for its scalar callers the state's block arrays and
// the workspace's cos and sin (the bond stage reads the blocks from their records instead: records.hpp).
struct BondArrays {
  const int *bi, *bj;
  const double *x, *y, *theta, *vx, *vy, *omega, *c, *s;
  const double *rix, *riy, *rjx, *rjy, *n0x, *n0y, *L, *inv_L, *K, *Ks, *KI, *mu;

  BondArrays(const Model<2>& m, const ModelState<2>& st, const Workspace<2>& w)
      : bi(m.bi.data()), bj(m.bj.data()), x(st.x.data()), y(st.y.data()), theta(st.theta.data()),
        vx(st.vx.data()), vy(st.vy.data()), omega(st.omega.data()), c(w.cos_t.data()), s(w.sin_t.data()),
        rix(m.frame.rix.data()), riy(m.frame.riy.data()), rjx(m.frame.rjx.data()), rjy(m.frame.rjy.data()),
        n0x(m.frame.n0x.data()), n0y(m.frame.n0y.data()), L(m.frame.L.data()), inv_L(m.frame.inv_L.data()),
        K(m.frame.K.data()), Ks(m.frame.Ks.data()), KI(m.frame.KI.data()), mu(m.frame.mu_bonded.data()) {}
  BlockKin block(int k) const { return {x[k], y[k], theta[k], vx[k], vy[k], omega[k], c[k], s[k]}; }
};

// Bond b between blocks I = bi[b] and J = bj[b]. `fs` is the linear part's shear history; its new value is out.fsl
// (dt = 0 evaluates without advancing it). `keep` (1 - damage) scales the parallel bond's forces in the slot; fnb,
// fsb and mb stay the undamaged forces the failure index reads.
[[gnu::always_inline]] inline BondEval eval_bond(const BondArrays& a, int b, const BlockKin& I, const BlockKin& J,
                                                 double dt, double fs, double keep) {
  BondEval out;
  const double ci = I.c, si = I.s, cj = J.c, sj = J.s;
  // Material points of the bond on each block, and the co-rotated frame: the bisector of the two rotated normals,
  // R_i n0 + R_j n0 = 2 cos(dtheta / 2) R_mean n0 (normalised by a series while |dtheta| is small: the series is
  // exact to round-off there and the square root is taken only to be discarded).
  const double rix = ci * a.rix[b] - si * a.riy[b], riy = si * a.rix[b] + ci * a.riy[b];
  const double rjx = cj * a.rjx[b] - sj * a.rjy[b], rjy = sj * a.rjx[b] + cj * a.rjy[b];
  const double gx = (J.x + rjx) - (I.x + rix), gy = (J.y + rjy) - (I.y + riy);
  const double dth = J.theta - I.theta;
  double nx = (ci + cj) * a.n0x[b] - (si + sj) * a.n0y[b];
  double ny = (si + sj) * a.n0x[b] + (ci + cj) * a.n0y[b];
  const double d2 = dth * dth;
  const double series = 0.5 * (1.0 + d2 * (0.125 + d2 * (5.0 / 384.0)));
  const double exact = 1.0 / std::sqrt(nx * nx + ny * ny);
  const double inv = std::abs(dth) < 0.05 ? series : exact;
  nx *= inv, ny *= inv;
  const double tx = -ny, ty = nx;
  const double dn = gx * nx + gy * ny, ds = gx * tx + gy * ty;
  // The parallel bond.
  const ParallelBond::Forces pb = ParallelBond::forces(a.K[b], a.Ks[b], a.KI[b], dn, ds, dth);
  out.fnb = pb.fn, out.fsb = pb.fs, out.mb = pb.m;
  // The linear part: the linear contact law on the compressed part of the edge.
  const LinearContact linear{a.K[b], a.Ks[b], a.mu[b], a.inv_L[b]};
  const EdgeOverlap eo = edge_overlap(a.L[b], dn, dth);
  out.fnl = linear.normal_force(eo.area, eo.chord);
  const double cix = rix + 0.5 * gx, ciy = riy + 0.5 * gy;  // bond point relative to each centroid
  const double cjx = rjx - 0.5 * gx, cjy = rjy - 0.5 * gy;
  out.px = I.x + cix, out.py = I.y + ciy;
  const double vrx = (J.vx - J.omega * cjy) - (I.vx - I.omega * ciy);
  const double vry = (J.vy + J.omega * cjx) - (I.vy + I.omega * cix);
  out.fsl = linear.shear_force(out.fnl, linear.trial_shear(eo.chord, vrx * tx + vry * ty, dt, fs));
  fs = out.fsl;
  const double flx = out.fnl * nx + fs * tx, fly = out.fnl * ny + fs * ty;
  const double fx = keep * (out.fnb * nx + out.fsb * tx) + flx, fy = keep * (out.fnb * ny + out.fsb * ty) + fly;
  const double lever = cross(eo.s_c * tx, eo.s_c * ty, flx, fly);  // the linear part acts at s_c along the edge
  out.fx = fx, out.fy = fy;
  out.mj = cross(cjx, cjy, fx, fy) + lever + keep * out.mb;
  out.mi = -cross(cix, ciy, fx, fy) - lever - keep * out.mb;
  return out;
}

// Bond b, its blocks read from the arrays.
inline BondEval eval_bond(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int b, double dt, double fs,
                          double keep) {
  const BondArrays a(m, s, w);
  return eval_bond(a, b, a.block(a.bi[b]), a.block(a.bj[b]), dt, fs, keep);
}

}  // namespace rbdem::stages
