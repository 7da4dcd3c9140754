// The platens: two rigid walls, the top one at ModelState::top_y closing at platen_velocity, the bottom one fixed
// at the specimen's lowest point. Each acts on the candidate blocks as a half-plane with the linear contact law
// (dem/laws/linear_contact.hpp), k_n from the block's mirror image (d = 2 x inradius). See stages.hpp.
#include <cmath>

#include "dem/contact_geometry.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

void platen_forces(const Model& m, ModelState& s, Workspace& w, double platen_friction, bool platens,
                   const StepContext& c) {
  if (c.advance) s.top_force = s.bottom_force = s.platen_energy = 0.0;
  if (!platens) return;
  double top_total = 0.0, bottom_total = 0.0, energy = 0.0;
  for (int side = 0; side < 2; ++side) {
    const bool top = side == 0;
    const auto& cand = top ? s.top_candidates : s.bottom_candidates;
    auto& fs_hist = top ? s.top_fs : s.bottom_fs;
    const double wy = top ? s.top_y : m.ymin;
    const double my = top ? 1.0 : -1.0;  // into the platen
    const double wall_vy = top ? -s.platen_velocity : 0.0;
    double total = 0.0;
    for (int b : cand) {
      double v[6];
      block_vertices(m, s, w, b, v);
      Overlap ov;
      if (!overlap_halfplane(v, 3, 0.0, wy, 0.0, my, ov)) {
        if (c.advance) fs_hist[b] = 0.0;
        continue;
      }
      const LinearContact law = m.platen_law(b, platen_friction);
      const double fn = law.normal_force(ov.area, ov.chord);
      // Force on the block: -fn along the normal (out of the platen), shear along t = perp(n).
      const double nx = ov.nx, ny = ov.ny, tx = -ny, ty = nx;
      const double rx = ov.px - s.x[b], ry = ov.py - s.y[b];
      const double vrx = s.vx[b] - s.omega[b] * ry, vry = s.vy[b] + s.omega[b] * rx - wall_vy;
      const double vt = vrx * tx + vry * ty;
      double fs = fs_hist[b];
      if (law.update_shear(fn, ov.chord, vt, c.dt, fs) && c.advance) s.e_friction += std::abs(fs * vt * c.dt);
      if (c.advance) fs_hist[b] = fs;
      const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;
      w.cfx[b] += fx, w.cfy[b] += fy, w.cm[b] += cross(rx, ry, fx, fy);
      total += fn;
      energy += law.strain_energy(fn, fs, ov.chord);
    }
    (top ? top_total : bottom_total) = total;
  }
  if (!c.advance) return;
  s.top_force = top_total, s.bottom_force = bottom_total, s.platen_energy = energy;
  s.e_work += s.top_force * s.platen_velocity * c.dt;
}

}  // namespace rbdem::stages
