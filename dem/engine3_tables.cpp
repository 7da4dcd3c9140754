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
    Slot sl;
    bond_slot(b, s, 0.0, nullptr, sl);
    const std::size_t i = std::size_t(m.bi[b]), j = std::size_t(m.bj[b]);
    const stages::FaceKinematics k =
        stages::face_kinematics(m.frame[b], {s.position(i), s.rotation(i), s.velocity(i), s.spin(i)},
                                {s.position(j), s.rotation(j), s.velocity(j), s.spin(j)});
    const Vec3 normal = k.frame.r[2];
    const Vec3 lever = sl.p - s.position(j);  // the bond point from j's centroid
    const Vec3 couple = sl.mj - cross(lever, sl.f);
    t.intact[b] = s.broken[b] ? 0 : 1;
    append(t.point, sl.p), append(t.normal, normal), append(t.force, sl.f), append(t.moment, couple);
    const double fn = dot(sl.f, normal);  // on j along n from i to j: positive in compression
    const Vec3 shear = sl.f - fn * normal;
    t.normal_force[b] = -fn, t.shear_force[b] = norm(shear);
    t.failure_index[b] = sl.index;
    t.damage[b] = 1.0 - sl.keep;
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
    Slot sl;
    bond_slot(b, s, 0.0, nullptr, sl);
    const FaceStiffness& k = m.frame[b].k;
    if (!s.broken[b]) e.strain += sl.keep * FaceBond::strain_energy(k, sl.pb);
    const FaceLinearPart& l = sl.linear;
    e.strain += 0.5 * (l.fn * l.fn / k.kn + (l.fs1 * l.fs1 + l.fs2 * l.fs2) / k.ks);
  }
  for (const BoundaryHooks<3>* h : hooks_) e.strain += h->stored_energy(), e.work += h->work_done();
  e.damping = s.e_damping, e.friction = s.e_friction;
  return e;
}

}  // namespace rbdem
