// The jacket: a confining pressure on the specimen's outer edges, as a membrane would apply it (docs/model.md,
// "Confined compression"). See stages.hpp.
//
// Each outer edge that is not on a platen carries the follower force F = -p t L n, L n the edge's current length
// times its current outward normal, at its current midpoint; the work p does is booked (the watchdog counts it as
// energy put in). The rule for a jacket that loses contact: an edge carries pressure while its block is part of the
// specimen, i.e. still has an intact bond or a contact that carries force this step. A block that lost every bond
// and every contact (a fragment that flew off) gets no pressure: a membrane would span the gap rather than push a
// loose fragment back, and a constant force on a free block would accelerate it without bound. Such edges are
// counted (ModelState::jacket_lost, and the most at any step, jacket_lost_max, in summary.json).
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

void jacket_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c) {
  if (!(s.confining_pressure > 0.0)) {
    if (c.advance) s.jacket_lost = 0;
    return;
  }
  // Blocks in a contact that carries force this step (the contact stage's records).
  const std::size_t nb = m.num_blocks();
  w.touching.assign(nb, 0);
  for (const std::vector<int>& list : w.in_contact)
    for (int p : list) {
      const Workspace::PairForce& f = w.pair_force[std::size_t(p)];
      if (f.fx != 0.0 || f.fy != 0.0) w.touching[std::size_t(s.contacts.i[p])] = w.touching[std::size_t(s.contacts.j[p])] = 1;
    }
  const double pt = s.confining_pressure * m.thickness;
  int lost = 0;
  double work = 0.0;
  const auto& J = m.jacket;
  for (std::size_t e = 0; e < J.size(); ++e) {
    const int b = J.block[e];
    const std::size_t k = std::size_t(b);
    if (!w.touching[k] && !m.has_intact_bond(b, s.broken)) {
      ++lost;
      continue;
    }
    const double co = w.cos_t[k], si = w.sin_t[k];
    const double ax = co * J.ax[e] - si * J.ay[e], ay = si * J.ax[e] + co * J.ay[e];
    const double bx = co * J.bx[e] - si * J.by[e], by = si * J.bx[e] + co * J.by[e];
    // L n = (dy, -dx) for the edge a -> b: the outside is to its right.
    const double fx = -pt * (by - ay), fy = pt * (bx - ax);
    const double rx = 0.5 * (ax + bx), ry = 0.5 * (ay + by);  // midpoint relative to the centroid
    w.cfx[k] += fx, w.cfy[k] += fy, w.cm[k] += cross(rx, ry, fx, fy);
    work += fx * (s.vx[k] - s.omega[k] * ry) + fy * (s.vy[k] + s.omega[k] * rx);
  }
  if (!c.advance) return;
  s.jacket_lost = lost;
  s.jacket_lost_max = std::max(s.jacket_lost_max, lost);
  s.e_work_jacket += work * c.dt;
}

}  // namespace rbdem::stages
