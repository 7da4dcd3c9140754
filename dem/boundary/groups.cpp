// Block groups of the 2D model: chosen blocks held fixed, moved at a prescribed velocity, loaded by a constant
// force, or moved rigidly by a servo, each degree of freedom its own way. See components.hpp.
//
// A group that is not a force group (its dofs fixed, prescribed or under a servo) holds its blocks fixed in the
// integrator (their state is kept); after each step it moves them by its velocity along each dof times the step and
// sets their velocities, so they push the rest of the model as a rigid displacement would. A servo dof's velocity
// comes from the reaction of that step (GroupServo). Its reading is the reaction: the sum of the forces on its blocks
// in the last step. A force group adds its force to each of its blocks after the contacts and the other components.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "dem/boundary/components.hpp"

namespace rbdem {

namespace {
using Mode = GroupSettings::Mode;

const char* mode_name(Mode m) {
  return m == Mode::fixed ? "fixed" : m == Mode::velocity ? "velocity" : m == Mode::force ? "force"
         : m == Mode::servo ? "servo" : "free";
}

// Refuses settings a group cannot follow: per-dof modes of the wrong count or mixing force with the others, values
// missing, a servo without a gain or a rate limit.
void check_settings(const GroupSettings& g) {
  if (!g.modes.empty() && g.modes.size() != 3)
    throw std::invalid_argument(fmt::format("block group '{}': give 3 modes (x, y and the rotation), not {}", g.name,
                                            g.modes.size()));
  const auto uses = [&g](Mode m) {
    return g.modes.empty() ? g.mode == m : std::find(g.modes.begin(), g.modes.end(), m) != g.modes.end();
  };
  const bool all_fixed = g.modes.empty() ? g.mode == Mode::fixed
                                         : std::count(g.modes.begin(), g.modes.end(), Mode::fixed) == 3;
  if (!g.modes.empty() && uses(Mode::force) && std::count(g.modes.begin(), g.modes.end(), Mode::force) != 3)
    throw std::invalid_argument(fmt::format("block group '{}': a force dof (each block on its own) does not mix with "
                                            "fixed, velocity, servo or free ones (the group as one body); use free for "
                                            "a load on the whole group",
                                            g.name));
  if (!all_fixed && g.value.size() != 3)
    throw std::invalid_argument(fmt::format("block group '{}': give 3 values (x, y and the rotation) for its {}",
                                            g.name, g.modes.empty() ? mode_name(g.mode) : "modes"));
  if (uses(Mode::servo) && !(g.servo.gain > 0 && g.servo.max_velocity > 0))
    throw std::invalid_argument(fmt::format("block group '{}': a servo needs a gain > 0 and a max_velocity > 0 (now {} "
                                            "and {})",
                                            g.name, g.servo.gain, g.servo.max_velocity));
}
}  // namespace

BlockGroupImpl<2>::BlockGroupImpl(Engine<2>& engine, const GroupSettings& settings)
    : engine_(engine), settings_(settings) {
  const std::size_t nb = engine.model().num_blocks();
  std::sort(settings_.blocks.begin(), settings_.blocks.end());
  settings_.blocks.erase(std::unique(settings_.blocks.begin(), settings_.blocks.end()), settings_.blocks.end());
  for (int b : settings_.blocks)
    if (b < 0 || std::size_t(b) >= nb)
      throw std::invalid_argument(fmt::format("block group '{}': block {} is not in the model ({} blocks)",
                                              settings_.name, b, nb));
  check_settings(settings_);
  if (mode(0) != Mode::force)
    for (int b : settings_.blocks) engine.fix_block(b);
}

void BlockGroupImpl<2>::set_value(const std::vector<double>& value) {
  if (mode(0) == Mode::fixed && mode(1) == Mode::fixed && mode(2) == Mode::fixed)
    throw std::invalid_argument(fmt::format("block group '{}' is fixed: it takes no velocity or force", settings_.name));
  if (value.size() != 3)
    throw std::invalid_argument(fmt::format("block group '{}': give 3 values (x, y and the rotation), not {}",
                                            settings_.name, value.size()));
  settings_.value = value;
}

std::vector<double> BlockGroupImpl<2>::velocity() const {
  if (settings_.modes.empty() && settings_.mode == Mode::velocity) return settings_.value;
  return velocity_;
}

void BlockGroupImpl<2>::set_modes(const std::vector<Mode>& modes) {
  GroupSettings g = settings_;
  g.modes = modes;
  check_settings(g);
  const bool was_force = mode(0) == Mode::force, is_force = modes.size() == 3 && modes[0] == Mode::force;
  if (was_force || is_force)
    throw std::invalid_argument(fmt::format("block group '{}': its blocks cannot change between moving on their own "
                                            "(force) and moving with the group; use another group",
                                            settings_.name));
  settings_.modes = modes;
}

void BlockGroupImpl<2>::set_servo(const GroupServo& servo) {
  GroupSettings g = settings_;
  g.servo = servo;
  check_settings(g);
  settings_.servo = servo;
}

std::vector<double> BlockGroupImpl<2>::attachment_stiffness() const {
  const Model<2>& m = engine_.model();
  std::vector<std::uint8_t> in(m.num_blocks(), 0);
  for (int b : settings_.blocks) in[std::size_t(b)] = 1;
  std::vector<double> k(3, 0.0);
  for (std::size_t e = 0; e < m.num_bonds(); ++e) {
    const int i = m.bi[e], j = m.bj[e];
    if (in[std::size_t(i)] == in[std::size_t(j)]) continue;
    // Along the bond normal the parallel bond and the closed linear part, across it their shear stiffnesses; the
    // rotation of the group's block about its centroid turns the bond point on its lever arm r too.
    const BondStiffness st = m.stiffness(int(e));
    const double kn = st.kbnA + st.knA, ks = st.kbsA + st.ksA;
    const double nx = m.frame.n0x[e], ny = m.frame.n0y[e];
    const bool group_is_i = in[std::size_t(i)] != 0;
    const double rx = group_is_i ? m.frame.rix[e] : m.frame.rjx[e], ry = group_is_i ? m.frame.riy[e] : m.frame.rjy[e];
    const double r_cross_n = rx * ny - ry * nx, r_dot_n = rx * nx + ry * ny;
    k[0] += kn * nx * nx + ks * ny * ny;
    k[1] += kn * ny * ny + ks * nx * nx;
    k[2] += st.kbnI + kn * r_cross_n * r_cross_n + ks * r_dot_n * r_dot_n;
  }
  return k;
}

std::vector<double> BlockGroupImpl<2>::displacement() const {
  const Model<2>& m = engine_.model();
  const ModelState<2>& s = engine_.state();
  std::vector<double> d(2, 0.0);
  for (int b : settings_.blocks) d[0] += s.x[std::size_t(b)] - m.x0[std::size_t(b)], d[1] += s.y[std::size_t(b)] - m.y0[std::size_t(b)];
  const double n = double(std::max<std::size_t>(settings_.blocks.size(), 1));
  return {d[0] / n, d[1] / n};
}

std::vector<std::pair<std::string, double>> BlockGroupImpl<2>::readings() const {
  const std::vector<double> d = displacement();
  std::vector<std::pair<std::string, double>> r = {{"force_x_n", force_[0]},        {"force_y_n", force_[1]},
                                                   {"moment_n_m", force_[2]},       {"displacement_x_m", d[0]},
                                                   {"displacement_y_m", d[1]},      {"work_j", work_}};
  if (!settings_.modes.empty() || settings_.mode == Mode::servo) {  // a group that moves each dof its own way
    r.push_back({"velocity_x_m_s", velocity_[0]});
    r.push_back({"velocity_y_m_s", velocity_[1]});
    r.push_back({"velocity_rotation_rad_s", velocity_[2]});
  }
  return r;
}

void BlockGroupImpl<2>::forces_end(const Model<2>&, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  if (mode(0) != Mode::force) return;
  const double* f = settings_.value.data();
  double power = 0.0;
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    w.cfx[k] += f[0], w.cfy[k] += f[1], w.cm[k] += f[2];
    power += f[0] * s.vx[k] + f[1] * s.vy[k] + f[2] * s.omega[k];
  }
  if (c.advance) work_ += power * c.dt;
}

// The speed along dof d for the next step: the prescribed one, the servo's from the reaction F just summed, a free
// dof's from its central difference, or 0.
double BlockGroupImpl<2>::dof_velocity(int d, const std::vector<double>& displacement, double dt) const {
  const Mode md = mode(d);
  if (md == Mode::velocity) return settings_.value[std::size_t(d)];
  if (md == Mode::free) {
    // The group as one body: its blocks' mass (the sum of their inertias for the rotation), Cundall's local damping
    // on the net force as each block gets it (dem/stages/integrator.cpp).
    const Model<2>& m = engine_.model();
    double mass = 0;
    for (int b : settings_.blocks) mass += d < 2 ? m.mass[std::size_t(b)] : m.inertia[std::size_t(b)];
    const double v = velocity_[std::size_t(d)], f = force_[std::size_t(d)] + settings_.value[std::size_t(d)];
    const double damped = f - engine_.options().damping * std::abs(f) * (v > 0 ? 1.0 : v < 0 ? -1.0 : 0.0);
    return v + dt * damped / mass;
  }
  if (md != Mode::servo) return 0.0;
  const GroupServo& sv = settings_.servo;
  double u = d < 2 ? displacement[std::size_t(d)] : 0.0;
  if (d == 2 && sv.stiffness != 0.0) {  // the mean rotation of the blocks
    for (int b : settings_.blocks) u += engine_.state().theta[std::size_t(b)];
    u /= double(std::max<std::size_t>(settings_.blocks.size(), 1));
  }
  const double load = settings_.value[std::size_t(d)] - sv.stiffness * (u - sv.origin);
  return std::clamp(sv.gain * (load + force_[std::size_t(d)]), -sv.max_velocity, sv.max_velocity);
}

void BlockGroupImpl<2>::after_step(const Model<2>&, ModelState<2>& s, Workspace<2>& w, double dt) {
  force_.assign(3, 0.0);
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    force_[0] += s.fx[k], force_[1] += s.fy[k], force_[2] += s.moment[k];
  }
  const bool moves = settings_.modes.empty() ? settings_.mode == Mode::velocity || settings_.mode == Mode::servo
                                             : mode(0) != Mode::force;
  if (!moves) return;
  // The velocity along each dof: a velocity group's value as it is; per-dof modes and servos one by one.
  std::array<double, 3> vel{};
  if (settings_.modes.empty() && settings_.mode == Mode::velocity) {
    vel = {settings_.value[0], settings_.value[1], settings_.value[2]};
  } else {
    const std::vector<double> u = displacement();
    for (int d = 0; d < 3; ++d) vel[std::size_t(d)] = dof_velocity(d, u, dt);
  }
  velocity_ = {vel[0], vel[1], vel[2]};
  // The group pushes the rest of the model with the opposite of the force on its blocks: its work is -F . v dt.
  const double* v = vel.data();
  work_ -= (force_[0] * v[0] + force_[1] * v[1] + force_[2] * v[2]) * dt;
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    s.x[k] += v[0] * dt, s.y[k] += v[1] * dt, s.theta[k] += v[2] * dt;
    s.vx[k] = v[0], s.vy[k] = v[1], s.omega[k] = v[2];
  }
  stages::update_rotations_of(s, w, settings_.blocks);
}

// A force group: its force at each block's centroid and its moment as a couple. A fixed, driven, servo or free
// group: the reaction that holds each block now, the opposite of the resultant of every other force on it, at its centroid.
void BlockGroupImpl<2>::loads(const Model<2>&, const ModelState<2>& s, const Workspace<2>&, int component,
                              const std::vector<double>& others, BoundaryLoads& out) const {
  const bool force = mode(0) == Mode::force;  // force mode is all dofs or none
  const double* f = settings_.value.data();
  for (int b : settings_.blocks) {
    const std::size_t k = std::size_t(b);
    if (force) append_load(out, b, component, s.x[k], s.y[k], f[0], f[1], f[2]);
    else append_load(out, b, component, s.x[k], s.y[k], -others[3 * k], -others[3 * k + 1], -others[3 * k + 2]);
  }
}

// A force group's forces are loads; any other group holds its blocks where they are (a prescribed or servo dof
// moves them only in the explicit run).
void BlockGroupImpl<2>::static_supports(const Model<2>&, StaticSupports2& supports) const {
  if (mode(0) == Mode::force) {
    if (supports.load.empty()) supports.load.assign(3 * engine_.model().num_blocks(), 0.0);
    for (int b : settings_.blocks)
      for (std::size_t d = 0; d < 3; ++d) supports.load[3 * std::size_t(b) + d] += settings_.value[d];
  } else {
    supports.fixed.insert(supports.fixed.end(), settings_.blocks.begin(), settings_.blocks.end());
  }
}

// A group with per-dof modes or a servo also stores its servo (set_servo changes it) and its velocity of the last
// step; the fields of the other groups are as they were.
void BlockGroupImpl<2>::save(Snapshot& s) const {
  const std::string p = "groups/" + settings_.name + "/";
  s.add(p + "work", Extent::scalar, work_);
  s.add(p + "force", Extent::free, force_);
  s.add(p + "blocks", Extent::free, settings_.blocks);
  s.add(p + "value", Extent::free, settings_.value);
  if (!settings_.modes.empty() || settings_.mode == Mode::servo) {
    const GroupServo& sv = settings_.servo;
    s.add(p + "servo", Extent::free, std::vector<double>{sv.gain, sv.max_velocity, sv.stiffness, sv.origin});
    s.add(p + "velocity", Extent::free, velocity_);
    std::vector<int> modes;
    for (Mode m : settings_.modes) modes.push_back(int(m));
    s.add(p + "modes", Extent::free, modes);
  }
}

void BlockGroupImpl<2>::load(const Snapshot& s, const Model<2>&) {
  const std::string p = "groups/" + settings_.name + "/";
  if (s.get<std::vector<int>>(p + "blocks") != settings_.blocks)
    throw std::invalid_argument(fmt::format("the snapshot's block group '{}' holds other blocks", settings_.name));
  work_ = s.get<double>(p + "work");
  force_ = s.get<std::vector<double>>(p + "force");
  settings_.value = s.get<std::vector<double>>(p + "value");
  if (s.has(p + "servo")) {  // per-dof modes (set_modes may have changed them) and the servo
    settings_.modes.clear();
    for (int m : s.get<std::vector<int>>(p + "modes")) settings_.modes.push_back(Mode(m));
    const std::vector<double>& sv = s.get<std::vector<double>>(p + "servo");
    if (sv.size() != 4)
      throw std::invalid_argument(
          fmt::format("the snapshot's block group '{}' has no servo of 4 values", settings_.name));
    settings_.servo = {sv[0], sv[1], sv[2], sv[3]};
    velocity_ = s.get<std::vector<double>>(p + "velocity");
  }
}

}  // namespace rbdem
