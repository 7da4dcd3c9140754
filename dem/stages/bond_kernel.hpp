// One bond's kinematics and forces: the inner body of the bond stage (bonds.cpp), also used by the bond events and
// the diagnostics (Engine::bond_forces). It reads the two blocks' kinematics and the bond's frame and calls the
// laws: ParallelBond::forces for the parallel bond, LinearContact on the bond's edge for the linear part (dem/laws/).
#pragma once

#include <cmath>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

// The forces of one bond in its co-rotated frame and what the slot receives.
struct BondEval {
  double fnb, fsb, mb;  // parallel bond, undamaged (N, N, N m)
  double fnl, fsl;      // linear part (N)
  double fx, fy, mi, mj;  // the slot: force on j, moments on i and j (damage applied)
  double px, py;        // bond point (world, m)
};

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// Bond b between blocks i and j. `fs` is the linear part's shear history in and out; dt = 0 evaluates without
// advancing it. `keep` (1 - damage) scales the parallel bond's forces in the slot; fnb, fsb and mb stay the
// undamaged forces the failure index reads.
[[gnu::always_inline]] inline void eval_bond(const Model& m, const ModelState& s, const Workspace& w, int b,
                                             double dt, double& fs, double keep, BondEval& out) {
  const BondFrames& f = m.frame;
  const std::size_t k = std::size_t(b);
  const int i = m.bi[k], j = m.bj[k];
  const double ci = w.cos_t[i], si = w.sin_t[i], cj = w.cos_t[j], sj = w.sin_t[j];
  // Material points of the bond on each block, and the co-rotated frame: the bisector of the two rotated normals,
  // R_i n0 + R_j n0 = 2 cos(dtheta / 2) R_mean n0 (normalised by a series while |dtheta| is small).
  const double rix = ci * f.rix[k] - si * f.riy[k], riy = si * f.rix[k] + ci * f.riy[k];
  const double rjx = cj * f.rjx[k] - sj * f.rjy[k], rjy = sj * f.rjx[k] + cj * f.rjy[k];
  const double gx = (s.x[j] + rjx) - (s.x[i] + rix), gy = (s.y[j] + rjy) - (s.y[i] + riy);
  const double dth = s.theta[j] - s.theta[i];
  double nx = (ci + cj) * f.n0x[k] - (si + sj) * f.n0y[k];
  double ny = (si + sj) * f.n0x[k] + (ci + cj) * f.n0y[k];
  const double d2 = dth * dth;
  const double inv = std::abs(dth) < 0.05 ? 0.5 * (1.0 + d2 * (0.125 + d2 * (5.0 / 384.0)))
                                          : 1.0 / std::sqrt(nx * nx + ny * ny);
  nx *= inv, ny *= inv;
  const double tx = -ny, ty = nx;
  const double dn = gx * nx + gy * ny, ds = gx * tx + gy * ty;
  // The parallel bond.
  const ParallelBond::Forces pb = ParallelBond::forces(f.K[k], f.Ks[k], f.KI[k], dn, ds, dth);
  out.fnb = pb.fn, out.fsb = pb.fs, out.mb = pb.m;
  // The linear part: the linear contact law on the compressed part of the edge.
  const BondKindLaw& law = m.law[int(m.kind[k])];
  const LinearContact linear{f.K[k], f.Ks[k], law.bonded_mu(), f.inv_L[k]};
  const EdgeOverlap eo = edge_overlap(f.L[k], dn, dth);
  out.fnl = linear.normal_force(eo.area, eo.chord);
  const double cix = rix + 0.5 * gx, ciy = riy + 0.5 * gy;  // bond point relative to each centroid
  const double cjx = rjx - 0.5 * gx, cjy = rjy - 0.5 * gy;
  out.px = s.x[i] + cix, out.py = s.y[i] + ciy;
  double vt = 0.0;
  if (out.fnl > 0.0) {
    const double vrx = (s.vx[j] - s.omega[j] * cjy) - (s.vx[i] - s.omega[i] * ciy);
    const double vry = (s.vy[j] + s.omega[j] * cjx) - (s.vy[i] + s.omega[i] * cix);
    vt = vrx * tx + vry * ty;
  }
  linear.update_shear(out.fnl, eo.chord, vt, dt, fs);
  out.fsl = fs;
  const double flx = out.fnl * nx + fs * tx, fly = out.fnl * ny + fs * ty;
  const double fx = keep * (out.fnb * nx + out.fsb * tx) + flx, fy = keep * (out.fnb * ny + out.fsb * ty) + fly;
  const double lever = cross(eo.s_c * tx, eo.s_c * ty, flx, fly);  // the linear part acts at s_c along the edge
  out.fx = fx, out.fy = fy;
  out.mj = cross(cjx, cjy, fx, fy) + lever + keep * out.mb;
  out.mi = -cross(cix, ciy, fx, fy) - lever - keep * out.mb;
}

}  // namespace rbdem::stages
