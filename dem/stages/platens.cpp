// The platens: two rigid walls, the top one at ModelState::top_y closing at platen_velocity, the bottom one fixed
// at the specimen's lowest point. Each acts on the candidate blocks as a half-plane with the linear contact law
// (dem/laws/linear_contact.hpp), k_n from the block's mirror image (d = 2 x inradius). See stages.hpp.
#include <algorithm>
#include <array>
#include <cmath>

#include <omp.h>

#include "dem/contact_geometry.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

// The contact of platen candidate k (the top platen's candidates first) into its record w.platen_force[k].
void platen_contact(const Model& m, ModelState& s, Workspace& w, double platen_friction, const StepContext& c,
                    int k) {
  const int ntop = int(s.top_candidates.size());
  Workspace::PlatenForce* out = w.platen_force.data();
  const bool top = k < ntop;
  const int b = top ? s.top_candidates[std::size_t(k)] : s.bottom_candidates[std::size_t(k - ntop)];
  const double wy = top ? s.top_y : m.ymin;
  const double my = top ? 1.0 : -1.0;  // into the platen
  const double wall_vy = top ? -s.platen_velocity : 0.0;
  double v[6];
  block_vertices(m, s, w, b, v);
  Overlap ov;
  double& fs_hist = (top ? s.top_fs : s.bottom_fs)[std::size_t(b)];  // each block once per platen
  if (!overlap_halfplane(v, 3, 0.0, wy, 0.0, my, ov)) {
    out[k] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, false};
    if (c.advance) fs_hist = 0.0;
    return;
  }
  const LinearContact law = m.platen_law(b, platen_friction);
  const double fn = law.normal_force(ov.area, ov.chord);
  // Force on the block: -fn along the normal (out of the platen), shear along t = perp(n).
  const double nx = ov.nx, ny = ov.ny, tx = -ny, ty = nx;
  const double rx = ov.px - s.x[b], ry = ov.py - s.y[b];
  const double vrx = s.vx[b] - s.omega[b] * ry, vry = s.vy[b] + s.omega[b] * rx - wall_vy;
  const double vt = vrx * tx + vry * ty;
  double fs = fs_hist;
  const double friction = law.update_shear(fn, ov.chord, vt, c.dt, fs) ? std::abs(fs * vt * c.dt) : 0.0;
  if (c.advance) fs_hist = fs;
  const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;
  out[k] = {fx, fy, cross(rx, ry, fx, fy), fn, law.strain_energy(fn, fs, ov.chord), friction, true};
}

}  // namespace

void platen_forces_begin(const Model& m, ModelState& s, Workspace& w, const StepContext& c) {
  if (c.advance) s.top_force = s.bottom_force = s.platen_energy = 0.0;
  partition(m, w, c.threads);
  w.platen_force.resize(s.top_candidates.size() + s.bottom_candidates.size());
}

void platen_forces_share(const Model& m, ModelState& s, Workspace& w, double platen_friction, bool platens,
                         const StepContext& c, int t, int nt) {
  if (!platens) return;
  // Each thread takes the candidates among the blocks it integrates (the lists are sorted by block): it reads the
  // blocks it moved itself.
  const std::array<int, 2> blocks = w.share(w.part.block, t, nt);
  const int b0 = blocks[0], b1 = blocks[1];
  auto mine = [&](const std::vector<int>& list, int& lo, int& hi) {
    lo = int(std::lower_bound(list.begin(), list.end(), b0) - list.begin());
    hi = int(std::lower_bound(list.begin(), list.end(), b1) - list.begin());
  };
  const int ntop = int(s.top_candidates.size());
  int lo, hi;
  mine(s.top_candidates, lo, hi);
  for (int k = lo; k < hi; ++k) platen_contact(m, s, w, platen_friction, c, k);
  mine(s.bottom_candidates, lo, hi);
  for (int k = lo; k < hi; ++k) platen_contact(m, s, w, platen_friction, c, ntop + k);
}

void platen_forces_end(ModelState& s, Workspace& w, bool platens, const StepContext& c) {
  if (!platens) return;
  const int ntop = int(s.top_candidates.size()), n = ntop + int(s.bottom_candidates.size());
  double top_total = 0.0, bottom_total = 0.0, energy = 0.0;
  for (int k = 0; k < n; ++k) {
    const bool top = k < ntop;
    const int b = top ? s.top_candidates[std::size_t(k)] : s.bottom_candidates[std::size_t(k - ntop)];
    const Workspace::PlatenForce& f = w.platen_force[std::size_t(k)];
    if (!f.touching) continue;
    if (c.advance) s.e_friction += f.friction;
    w.cfx[b] += f.fx, w.cfy[b] += f.fy, w.cm[b] += f.m;
    (top ? top_total : bottom_total) += f.fn;
    energy += f.energy;
  }
  if (!c.advance) return;
  s.top_force = top_total, s.bottom_force = bottom_total, s.platen_energy = energy;
  s.e_work += s.top_force * s.platen_velocity * c.dt;
}

// Each candidate's contact runs in parallel into its own record (the top platen's candidates, then the bottom
// one's); the records are then summed serially in that order, so the sums do not depend on the thread count.
void platen_forces(const Model& m, ModelState& s, Workspace& w, double platen_friction, bool platens,
                   const StepContext& c) {
  platen_forces_begin(m, s, w, c);
  const std::size_t n = s.top_candidates.size() + s.bottom_candidates.size();
#pragma omp parallel num_threads(c.threads) if (platens && n > 64)
  platen_forces_share(m, s, w, platen_friction, platens, c, omp_get_thread_num(), omp_get_num_threads());
  platen_forces_end(s, w, platens, c);
}

}  // namespace rbdem::stages
