// The platens of the 3D model. See components3.hpp.
//
// A platen acts on a block that crosses its plane through the linear contact law one dimension up, as the 2D platen
// does on the overlap area: F_n = k_n V on the overlap volume V (so a face of area A pressed by d carries
// k_n A d, the static solve's spring), at the overlap's centroid, and the incremental shear dF_s = -(k_n / kappa)
// A_c v_s dt on the section area A_c, Coulomb-limited to mu F_n. The candidates are the blocks within one block
// radius of a platen at rest; their contacts are computed side by side on the step's threads (prepare_forces) and
// summed serially in candidate order (the top platen's first), so the sums do not depend on the thread count.
#include <algorithm>
#include <cmath>

#include "dem/boundary/components3.hpp"
#include "dem/geometry3.hpp"

namespace rbdem {

namespace {

double tet_volume(Vec3 a, Vec3 b, Vec3 c, Vec3 d) { return std::abs(signed_volume({a, b, c, d})); }

// Adds tetrahedron (a, b, c, d) to the running volume and first moment.
void add_tet(Vec3 a, Vec3 b, Vec3 c, Vec3 d, double& volume, Vec3& moment) {
  const double v = tet_volume(a, b, c, d);
  volume += v, moment += (0.25 * v) * (a + b + c + d);
}

// The prism with triangles (a, b, c) and (a2, b2, c2), a to a2 and so on, split into three tetrahedra.
void add_prism(Vec3 a, Vec3 b, Vec3 c, Vec3 a2, Vec3 b2, Vec3 c2, double& volume, Vec3& moment) {
  add_tet(a, b, c, c2, volume, moment);
  add_tet(a, b, b2, c2, volume, moment);
  add_tet(a, a2, b2, c2, volume, moment);
}

double triangle_area(Vec3 a, Vec3 b, Vec3 c) { return 0.5 * norm(cross(b - a, c - a)); }

}  // namespace

TetOverlap tet_beyond_plane(const std::array<Vec3, 4>& v, const std::array<double, 4>& d) {
  TetOverlap o;
  int in[4], out[4], ni = 0, no = 0;
  for (int k = 0; k < 4; ++k) (d[std::size_t(k)] > 0 ? in[ni++] : out[no++]) = k;
  if (ni == 0) return o;
  // The point where edge (a inside, b outside) crosses the plane.
  auto cut = [&](int a, int b) {
    const double f = d[std::size_t(a)] / (d[std::size_t(a)] - d[std::size_t(b)]);
    return v[std::size_t(a)] + f * (v[std::size_t(b)] - v[std::size_t(a)]);
  };
  auto V = [&](int k) { return v[std::size_t(k)]; };
  Vec3 moment;
  if (ni == 4) {
    add_tet(V(0), V(1), V(2), V(3), o.volume, moment);
    double deepest = 0;
    for (double x : d) deepest = std::max(deepest, x);
    o.area = o.volume / deepest;  // a block wholly past the plane: the area of the slab of its volume
  } else if (ni == 1) {
    const int a = in[0];
    const Vec3 p = cut(a, out[0]), q = cut(a, out[1]), r = cut(a, out[2]);
    add_tet(V(a), p, q, r, o.volume, moment);
    o.area = triangle_area(p, q, r);
  } else if (ni == 3) {
    const int e = out[0];
    const Vec3 p = cut(in[0], e), q = cut(in[1], e), r = cut(in[2], e);
    add_prism(V(in[0]), V(in[1]), V(in[2]), p, q, r, o.volume, moment);
    o.area = triangle_area(p, q, r);
  } else {  // two inside (a, b), two outside (c, e): the prism (a, ac, ae) to (b, bc, be)
    const int a = in[0], b = in[1], c = out[0], e = out[1];
    const Vec3 ac = cut(a, c), ae = cut(a, e), bc = cut(b, c), be = cut(b, e);
    add_prism(V(a), ac, ae, V(b), bc, be, o.volume, moment);
    o.area = triangle_area(ac, ae, be) + triangle_area(ac, be, bc);
  }
  if (o.volume > 0) o.centroid = (1.0 / o.volume) * moment;
  return o;
}

PlatensImpl<3>::PlatensImpl(const Model<3>& m, const PlatenSettings& settings)
    : zmin_(m.lo.z), zmax_(m.hi.z), area_(m.loaded_area), friction_(settings.friction), top_z_(m.hi.z),
      velocity_(settings.velocity) {
  const std::size_t nb = m.num_blocks();
  kn_.resize(nb), kappa_.resize(nb);
  double reach = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const FaceKindLaw& rock = m.law[0];
    kn_[b] = rock.modulus / (2.0 * m.inradius[b]), kappa_[b] = rock.kappa;
    for (const Vec3& r : m.shape[b]) reach = std::max(reach, norm(r));
  }
  for (std::size_t b = 0; b < nb; ++b) {
    double lo = m.x0[b].z, hi = lo;
    for (const Vec3& r : m.shape[b]) lo = std::min(lo, m.x0[b].z + r.z), hi = std::max(hi, m.x0[b].z + r.z);
    if (hi > zmax_ - reach) top_candidates_.push_back(int(b));
    if (lo < zmin_ + reach) bottom_candidates_.push_back(int(b));
  }
  fs_.assign(2 * (top_candidates_.size() + bottom_candidates_.size()), 0.0);
  contacts_.resize(top_candidates_.size() + bottom_candidates_.size());
}

std::vector<std::pair<std::string, double>> PlatensImpl<3>::readings() const {
  return {{"top_force_n", top_force_},   {"bottom_force_n", bottom_force_}, {"closure_m", closure()},
          {"velocity_m_s", velocity_},   {"stress_pa", stress()},           {"work_j", work_},
          {"energy_j", energy_},         {"servo", servo_on_ ? 1.0 : 0.0}};
}

PlatensImpl<3>::Contact PlatensImpl<3>::contact(const Model<3>& m, const ModelState<3>& s, int block, bool top,
                                                 double dt, Vec3& fs) const {
  Contact c;
  const std::size_t b = std::size_t(block);
  const Vec3 x = s.position(b);
  const Quat q = s.rotation(b);
  std::array<Vec3, 4> v;
  std::array<double, 4> depth;
  for (std::size_t k = 0; k < 4; ++k) {
    v[k] = x + rotate(q, m.shape[b][k]);
    depth[k] = top ? v[k].z - top_z_ : zmin_ - v[k].z;
  }
  const TetOverlap o = tet_beyond_plane(v, depth);
  if (!(o.volume > 0)) {
    fs = {};
    return c;
  }
  const double sign = top ? -1.0 : 1.0;  // the force on the block along z: down from the top platen
  c.fn = kn_[b] * o.volume;
  // The shear: the block's velocity at the overlap's centroid along x and y (the platens do not move sideways).
  const Vec3 r = o.centroid - x;
  const Vec3 vp = s.velocity(b) + cross(s.spin(b), r);
  const double ks_area = kn_[b] / kappa_[b] * o.area;
  Vec3 shear{fs.x - ks_area * vp.x * dt, fs.y - ks_area * vp.y * dt, 0.0};
  const double mag = norm(shear), limit = friction_ * c.fn;
  if (mag > limit) {
    shear = (mag > 0 ? limit / mag : 0.0) * shear;
    c.friction = std::abs(dot(shear, vp)) * dt;
  }
  fs = shear;
  c.force = {shear.x, shear.y, sign * c.fn};
  c.point = o.centroid;
  c.energy = 0.5 * c.fn * c.fn / (kn_[b] * o.area) + (ks_area > 0 ? 0.5 * dot(shear, shear) / ks_area : 0.0);
  c.touching = true;
  return c;
}

void PlatensImpl<3>::prepare_forces(const Model<3>& m, const ModelState<3>& s, double dt, int thread, int threads) {
  const std::size_t ntop = top_candidates_.size();
  const std::size_t n = ntop + bottom_candidates_.size();
  // contacts_ holds one entry per candidate from the constructor on; thread 0 alone marks it filled (add_forces
  // reads the mark after the engine's barrier).
  if (thread == 0) prepared_ = true;
  const std::size_t lo = n * std::size_t(thread) / std::size_t(threads);
  const std::size_t hi = n * std::size_t(thread + 1) / std::size_t(threads);
  for (std::size_t k = lo; k < hi; ++k) {
    const bool top = k < ntop;
    const int b = top ? top_candidates_[k] : bottom_candidates_[k - ntop];
    Vec3 fs{fs_[2 * k], fs_[2 * k + 1], 0.0};
    contacts_[k] = contact(m, s, b, top, dt, fs);
    fs_[2 * k] = fs.x, fs_[2 * k + 1] = fs.y;
  }
}

double PlatensImpl<3>::add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force,
                                  std::vector<Vec3>& moment, double dt, bool advance) {
  if (advance && servo_on_)
    velocity_ = std::clamp(servo_.gain * (servo_.target_stress - stress()), -servo_.max_velocity, servo_.max_velocity);
  double totals[2] = {0, 0}, energy = 0, friction = 0;
  const std::size_t ntop = top_candidates_.size();
  const std::size_t n = ntop + bottom_candidates_.size();
  const bool prepared = advance && prepared_;
  prepared_ = false;
  for (std::size_t k = 0; k < n; ++k) {
    const bool top = k < ntop;
    const int b = top ? top_candidates_[k] : bottom_candidates_[k - ntop];
    Contact c;
    if (prepared) {
      c = contacts_[k];
    } else {
      Vec3 fs{fs_[2 * k], fs_[2 * k + 1], 0.0};
      c = contact(m, s, b, top, dt, fs);
      if (advance) fs_[2 * k] = fs.x, fs_[2 * k + 1] = fs.y;
    }
    if (!c.touching) continue;
    force[std::size_t(b)] += c.force;
    moment[std::size_t(b)] += cross(c.point - s.position(std::size_t(b)), c.force);
    totals[top ? 0 : 1] += c.fn, energy += c.energy, friction += c.friction;
  }
  if (!advance) return 0.0;
  top_force_ = totals[0], bottom_force_ = totals[1], energy_ = energy;
  work_ += top_force_ * velocity_ * dt;
  return friction;
}

void PlatensImpl<3>::loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const {
  const std::size_t ntop = top_candidates_.size();
  for (std::size_t k = 0; k < ntop + bottom_candidates_.size(); ++k) {
    const bool top = k < ntop;
    const int b = top ? top_candidates_[k] : bottom_candidates_[k - ntop];
    Vec3 fs{fs_[2 * k], fs_[2 * k + 1], 0.0};
    const Contact c = contact(m, s, b, top, 0.0, fs);
    if (!c.touching) continue;
    out.block.push_back(b), out.component.push_back(component);
    out.point.insert(out.point.end(), {c.point.x, c.point.y, c.point.z});
    out.force.insert(out.force.end(), {c.force.x, c.force.y, c.force.z});
    out.moment.insert(out.moment.end(), {0.0, 0.0, 0.0});
  }
}

void PlatensImpl<3>::add_stiffness(const Model<3>& m, std::vector<BlockStiffness3>& k) const {
  for (const SurfaceFace& f : m.surface) {
    if (f.tag == FaceTag::lateral) continue;
    const std::size_t b = std::size_t(f.block);
    const double kn = kn_[b] * f.area;
    k[b].add(kn, kn / kappa_[b], kn_[b] * f.polar, f.r, {0.0, 0.0, 1.0});
  }
}

void PlatensImpl<3>::static_rows(const Model<3>& m, std::vector<PlatenRow3>& rows) const {
  for (const SurfaceFace& f : m.surface) {
    if (f.tag == FaceTag::lateral) continue;
    const std::size_t b = std::size_t(f.block);
    const double kn = kn_[b] * f.area;
    rows.push_back({f.block, f.tag == FaceTag::top, kn, friction_ > 0 ? kn / kappa_[b] : 0.0, f.r, kn_[b] * f.polar});
  }
}

void PlatensImpl<3>::apply_static(const Model<3>& m, const StaticResult& st, double factor) {
  top_z_ = zmax_ - factor * st.platen_displacement;
  // Sticking platens: each candidate's shear history from the displacement of its face on the platen.
  std::fill(fs_.begin(), fs_.end(), 0.0);
  if (!(friction_ > 0) || st.u.empty()) return;
  const std::size_t ntop = top_candidates_.size();
  for (const SurfaceFace& f : m.surface) {
    if (f.tag == FaceTag::lateral) continue;
    const bool top = f.tag == FaceTag::top;
    const auto& list = top ? top_candidates_ : bottom_candidates_;
    const auto it = std::lower_bound(list.begin(), list.end(), f.block);
    if (it == list.end() || *it != f.block) continue;
    const std::size_t k = std::size_t(it - list.begin()) + (top ? 0 : ntop), b = std::size_t(f.block);
    const double* u = &st.u[6 * b];
    const Vec3 slip = Vec3{u[0], u[1], u[2]} + cross({u[3], u[4], u[5]}, f.r);
    const double ks = kn_[b] / kappa_[b] * f.area;
    fs_[2 * k] -= factor * ks * slip.x, fs_[2 * k + 1] -= factor * ks * slip.y;
  }
}

void PlatensImpl<3>::save(Snapshot& s) const {
  s.add("platens/top_z", Extent::scalar, top_z_);
  s.add("platens/velocity", Extent::scalar, velocity_);
  s.add("platens/servo", Extent::scalar, servo_on_);
  s.add("platens/servo_target_stress", Extent::scalar, servo_.target_stress);
  s.add("platens/servo_gain", Extent::scalar, servo_.gain);
  s.add("platens/servo_max_velocity", Extent::scalar, servo_.max_velocity);
  s.add("platens/friction", Extent::scalar, friction_);
  s.add("platens/top_force", Extent::scalar, top_force_);
  s.add("platens/bottom_force", Extent::scalar, bottom_force_);
  s.add("platens/energy", Extent::scalar, energy_);
  s.add("platens/work", Extent::scalar, work_);
  s.add("platens/fs", Extent::free, fs_);
}

void PlatensImpl<3>::load(const Snapshot& s, const Model<3>&) {
  if (s.get<double>("platens/friction") != friction_)
    throw std::invalid_argument("the snapshot's platens have another friction coefficient");
  const auto& fs = s.get<std::vector<double>>("platens/fs");
  if (fs.size() != fs_.size()) throw std::invalid_argument("the snapshot's platens do not fit this model");
  top_z_ = s.get<double>("platens/top_z");
  velocity_ = s.get<double>("platens/velocity");
  servo_on_ = s.get<bool>("platens/servo");
  servo_ = {s.get<double>("platens/servo_target_stress"), s.get<double>("platens/servo_gain"),
            s.get<double>("platens/servo_max_velocity")};
  top_force_ = s.get<double>("platens/top_force");
  bottom_force_ = s.get<double>("platens/bottom_force");
  energy_ = s.get<double>("platens/energy");
  work_ = s.get<double>("platens/work");
  fs_ = fs;
}

}  // namespace rbdem
