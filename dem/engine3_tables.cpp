// The 3D engine's state as dimension-free tables and its energy accounts. See engine3.hpp and dem/state_tables.hpp.
#include <cmath>

#include "dem/engine3.hpp"

namespace rbdem {

namespace {

void append(std::vector<double>& v, Vec3 a) { v.insert(v.end(), {a.x, a.y, a.z}); }

}  // namespace

BlockStates Engine<3>::block_states() const {
  const ModelState<3>& s = state_;
  BlockStates t;
  t.dim = 3;
  for (std::size_t b = 0; b < s.num_blocks(); ++b) {
    append(t.position, s.position(b));
    append(t.rotation, rotation_vector(s.rotation(b)));
    append(t.velocity, s.velocity(b));
    append(t.angular_velocity, s.spin(b));
    append(t.force, {s.fx[b], s.fy[b], s.fz[b]});
    append(t.moment, {s.mx[b], s.my[b], s.mz[b]});
  }
  return t;
}

// Each bond's forces at the state now (its slot evaluated afresh, no history advanced): the force on j at the
// bond point, the couple on j about it, the normal force (tension positive) and the shear force's magnitude in
// the face now.
BondStates Engine<3>::bond_states() const {
  const Model<3>& m = model_;
  const ModelState<3>& s = state_;
  BondStates t;
  t.dim = 3;
  const std::size_t n = m.num_bonds();
  t.intact.resize(n), t.normal_force.resize(n), t.shear_force.resize(n), t.failure_index.resize(n), t.damage.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    double keep = 0;
    const stages::FaceBondOut e = bond_now(b, keep);
    const Vec3 p = s.position(std::size_t(m.bi[b])) + e.ci;
    const Vec3 couple = e.mj - cross(p - s.position(std::size_t(m.bj[b])), e.f);  // about the bond point
    t.intact[b] = s.broken[b] ? 0 : 1;
    append(t.point, p), append(t.normal, e.normal), append(t.force, e.f), append(t.moment, couple);
    const double fn = dot(e.f, e.normal);  // on j along n from i to j: positive in compression
    t.normal_force[b] = -fn, t.shear_force[b] = norm(e.f - fn * e.normal);
    bool tensile = false;
    using C = stages::FaceBondColumns;
    const BondLoad q = stages::face_bond_load(C::of(m.table, b), C::lane(b), e.pb);
    t.failure_index[b] = s.broken[b] ? 0.0 : q.index(tensile);
    t.damage[b] = 1.0 - keep;
  }
  return t;
}

BoundaryLoads Engine<3>::boundary_loads() const {
  BoundaryLoads out;
  out.dim = 3;
  for (std::size_t c = 0; c < hooks_.size(); ++c) hooks_[c]->loads(model_, state_, int(c), out);
  return out;
}

// Kinetic energy of the blocks; strain energy of the parallel bonds (their damaged share), of the linear parts
// (closed: 1/2 F^2 / K on the normal and the shear) and of the components; the damping's and the components'
// accounts.
Energies Engine<3>::energies() const {
  const Model<3>& m = model_;
  const ModelState<3>& s = state_;
  Energies e;
  for (std::size_t b = 0; b < s.num_blocks(); ++b)
    e.kinetic += kinetic_energy(m.body[b], {s.position(b), s.velocity(b), s.rotation(b), s.spin(b)});
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    double keep = 0;
    const stages::FaceBondOut ev = bond_now(b, keep);
    const FaceStiffness& k = m.frame[b].k;
    if (!s.broken[b]) e.strain += keep * FaceBond::strain_energy(k, ev.pb);
    e.strain += 0.5 * (ev.fn_lin * ev.fn_lin / k.kn + (ev.fs1_lin * ev.fs1_lin + ev.fs2_lin * ev.fs2_lin) / k.ks);
  }
  for (const BoundaryHooks<3>* h : hooks_) e.strain += h->stored_energy(), e.work += h->work_done();
  e.damping = s.e_damping, e.friction = s.e_friction;
  return e;
}

}  // namespace rbdem
