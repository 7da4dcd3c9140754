// The engine's state as the dimension-free tables of dem/state_tables.hpp (copies, for scripts, measurements and
// writers). See engine.hpp.
#include <algorithm>
#include <cmath>
#include <memory>

#include "dem/contact_geometry.hpp"
#include "dem/engine.hpp"
#include "dem/stages/bond_kernel.hpp"

namespace rbdem {

BlockStates Engine<2>::block_states() const {
  const ModelState<2>& s = state_;
  const std::size_t n = model_.num_blocks();
  BlockStates t;
  t.dim = 2;
  t.position.resize(2 * n), t.velocity.resize(2 * n), t.force.resize(2 * n);
  t.rotation = s.theta, t.angular_velocity = s.omega, t.moment = s.moment;
  for (std::size_t b = 0; b < n; ++b) {
    t.position[2 * b] = s.x[b], t.position[2 * b + 1] = s.y[b];
    t.velocity[2 * b] = s.vx[b], t.velocity[2 * b + 1] = s.vy[b];
    t.force[2 * b] = s.fx[b], t.force[2 * b + 1] = s.fy[b];
  }
  return t;
}

BondStates Engine<2>::bond_states() const {
  const ModelState<2>& s = state_;
  const std::size_t n = model_.num_bonds();
  BondStates t;
  t.dim = 2;
  t.intact.resize(n), t.point.assign(2 * n, 0.0), t.normal.assign(2 * n, 0.0), t.force.assign(2 * n, 0.0);
  t.moment.assign(n, 0.0), t.normal_force.assign(n, 0.0), t.shear_force.assign(n, 0.0);
  t.failure_index.assign(n, 0.0), t.damage.assign(n, 1.0);
  const BondFrames& f = model_.frame;
#pragma omp parallel for schedule(static) num_threads(threads()) if (n > 4096)
  for (std::size_t k = 0; k < n; ++k) {
    t.intact[k] = s.broken[k] ? 0 : 1;
    if (s.broken[k]) continue;
    const int b = int(k);
    const stages::BondEval ev = stages::eval_bond(model_, s, work_, b, 0.0, s.fs_lin[k], work_.keep[k]);
    const double keep = work_.keep[k];
    // The co-rotated frame of the evaluation: the bisector of the two rotated reference normals.
    const std::size_t i = std::size_t(model_.bi[k]), j = std::size_t(model_.bj[k]);
    const double ci = work_.cos_t[i] + work_.cos_t[j], si = work_.sin_t[i] + work_.sin_t[j];
    double nx = ci * f.n0x[k] - si * f.n0y[k], ny = si * f.n0x[k] + ci * f.n0y[k];
    const double len = std::hypot(nx, ny);
    nx /= len, ny /= len;
    const double cjx = ev.px - s.x[j], cjy = ev.py - s.y[j];
    t.point[2 * k] = ev.px, t.point[2 * k + 1] = ev.py;
    t.normal[2 * k] = nx, t.normal[2 * k + 1] = ny;
    t.force[2 * k] = ev.fx, t.force[2 * k + 1] = ev.fy;
    t.moment[k] = ev.mj - stages::cross(cjx, cjy, ev.fx, ev.fy);  // the couple about the bond point
    t.normal_force[k] = -(keep * ev.fnb + ev.fnl);
    t.shear_force[k] = keep * ev.fsb + ev.fsl;
    const BondLoad q = BondLoad::of(f.tension_limit[k], f.cohesion_A[k], f.tan_phi[k], f.beta_m[k], ev.fnb, ev.fsb,
                                    ev.mb, f.inv_L[k], model_.law[model_.material[k]].bond.moment_arm());
    bool tensile = false;
    t.failure_index[k] = q.index(tensile);
    t.damage[k] = 1.0 - keep;
  }
  return t;
}

ContactStates Engine<2>::contact_states() const {
  const ModelState<2>& s = state_;
  const ContactPairs& C = s.contacts;
  const std::size_t n = C.size();
  // The listed pairs that overlap now, with the contact law at the overlap now and the shear force as carried
  // (capped by friction): the forces the engine's force evaluation gives in this state (evaluate_forces). Each
  // pair's row on the run's threads (8 numbers: point, normal, force, normal and shear force), then the rows of the
  // pairs in contact in pair order.
  constexpr std::size_t width = 8;
  const auto row = std::make_unique_for_overwrite<double[]>(width * n);
  std::vector<std::uint8_t> touching(n, 0);
#pragma omp parallel for schedule(static) num_threads(threads()) if (n > 4096)
  for (std::size_t p = 0; p < n; ++p) {
    if (C.bond[p] >= 0 && !s.broken[std::size_t(C.bond[p])]) continue;  // still bonded: the bond is its contact
    Overlap ov;
    if (!stages::pair_overlap(model_, s, work_, p, ov)) continue;
    const double nx = -ov.nx, ny = -ov.ny, tx = -ny, ty = nx;  // from i to j
    const double fn = C.law[p].normal_force(ov.area, ov.chord);
    double fs = C.fs[p];
    C.law[p].update_shear(fn, ov.chord, 0.0, 0.0, fs);
    double* r = &row[width * p];
    r[0] = ov.px, r[1] = ov.py, r[2] = nx, r[3] = ny, r[4] = fn * nx + fs * tx, r[5] = fn * ny + fs * ty;
    r[6] = fn, r[7] = fs;
    touching[p] = 1;
  }
  ContactStates t;
  t.dim = 2;
  const std::size_t m = std::size_t(std::count(touching.begin(), touching.end(), std::uint8_t(1)));
  t.i.reserve(m), t.j.reserve(m), t.point.reserve(2 * m), t.normal.reserve(2 * m), t.force.reserve(2 * m);
  t.normal_force.reserve(m), t.shear_force.reserve(m);
  for (std::size_t p = 0; p < n; ++p) {
    if (!touching[p]) continue;
    const double* r = &row[width * p];
    t.i.push_back(C.i[p]), t.j.push_back(C.j[p]);
    t.point.insert(t.point.end(), {r[0], r[1]});
    t.normal.insert(t.normal.end(), {r[2], r[3]});
    t.force.insert(t.force.end(), {r[4], r[5]});
    t.normal_force.push_back(r[6]), t.shear_force.push_back(r[7]);
  }
  return t;
}

namespace {

// The resultant force and moment about the centroid (3 per block) of the bond and contact rows and the loads so far.
std::vector<double> resultants(const Model<2>& m, const ModelState<2>& s, const BondStates& bonds,
                               const ContactStates& contacts, const BoundaryLoads& loads) {
  std::vector<double> r(3 * s.x.size(), 0.0);
  const auto add = [&](int b, const double* p, double fx, double fy, double couple) {
    const std::size_t k = std::size_t(b);
    r[3 * k] += fx, r[3 * k + 1] += fy;
    r[3 * k + 2] += stages::cross(p[0] - s.x[k], p[1] - s.y[k], fx, fy) + couple;
  };
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const double* p = &bonds.point[2 * k];
    const double fx = bonds.force[2 * k], fy = bonds.force[2 * k + 1];
    add(m.bj[k], p, fx, fy, bonds.moment[k]);
    add(m.bi[k], p, -fx, -fy, -bonds.moment[k]);
  }
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const double* p = &contacts.point[2 * k];
    add(contacts.j[k], p, contacts.force[2 * k], contacts.force[2 * k + 1], 0.0);
    add(contacts.i[k], p, -contacts.force[2 * k], -contacts.force[2 * k + 1], 0.0);
  }
  for (std::size_t k = 0; k < loads.size(); ++k)
    add(loads.block[k], &loads.point[2 * k], loads.force[2 * k], loads.force[2 * k + 1], loads.moment[k]);
  return r;
}

}  // namespace

// The components that load blocks first; those that hold blocks (fixed and driven groups) last, with the resultant
// of everything else on each block, whose opposite is their reaction now.
BoundaryLoads Engine<2>::boundary_loads() const {
  BoundaryLoads t;
  t.dim = 2;
  const std::vector<double> none;
  for (std::size_t k = 0; k < hooks_.size(); ++k)
    if (!hooks_[k]->holds_blocks()) hooks_[k]->loads(model_, state_, work_, int(k), none, t);
  const bool holding = std::any_of(hooks_.begin(), hooks_.end(), [](const auto* h) { return h->holds_blocks(); });
  if (!holding) return t;
  const std::vector<double> others = resultants(model_, state_, bond_states(), contact_states(), t);
  for (std::size_t k = 0; k < hooks_.size(); ++k)
    if (hooks_[k]->holds_blocks()) hooks_[k]->loads(model_, state_, work_, int(k), others, t);
  return t;
}

}  // namespace rbdem
