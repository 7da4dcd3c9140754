// ModelState<3>: the complete mutable state of a 3D DEM model, and nothing else (the snapshot), as ModelState<2>
// (dem/state.hpp) is in 2D. One field table, fields(), which the snapshot, restore's size checks and the tests walk.
//
// Blocks: the centroid (x, y, z), the unit quaternion (qw, qx, qy, qz) that turns the block from its reference
// configuration, the velocity and the angular velocity (world) of the half step before, the force and moment of
// the last step (before damping). Bonds: broken, the linear part's shear history (two components in the face frame)
// and the softening drive.
#pragma once

#include <cstdint>
#include <vector>

#include "dem/records.hpp"
#include "dem/snapshot.hpp"
#include "dem/state.hpp"
#include "dem/vec3.hpp"

namespace rbdem {

template <>
struct ModelState<3> {
  // --- blocks ---
  std::vector<double> x, y, z, qw, qx, qy, qz;  // m; the rotation from rest
  std::vector<double> vx, vy, vz, wx, wy, wz;   // m/s, rad/s (world)
  std::vector<double> fx, fy, fz, mx, my, mz;   // N, N m: the last step's resultant before damping

  // --- bonds ---
  std::vector<std::uint8_t> broken;
  std::vector<double> fs1, fs2;  // N, the linear part's shear history in the face frame
  std::vector<double> drive;     // softening bonds: 0 below the strength, then the largest failure index reached

  // --- clock and accounts ---
  double dt = 0, time = 0;
  long steps = 0;
  bool breakage = true;
  double strain_for_log = 0;
  double e_damping = 0, e_friction = 0;  // J, cumulative
  std::vector<Crack> cracks;

  std::size_t num_blocks() const { return x.size(); }
  std::size_t num_bonds() const { return broken.size(); }

  Vec3 position(std::size_t b) const { return {x[b], y[b], z[b]}; }
  Quat rotation(std::size_t b) const { return {qw[b], qx[b], qy[b], qz[b]}; }
  Vec3 velocity(std::size_t b) const { return {vx[b], vy[b], vz[b]}; }
  Vec3 spin(std::size_t b) const { return {wx[b], wy[b], wz[b]}; }

  // The field table: f(name, field, extent) for every field above, in a fixed order.
  template <class F>
  void fields(F&& f) {
    visit_fields(*this, f);
  }
  template <class F>
  void fields(F&& f) const {
    visit_fields(*this, f);
  }

 private:
  template <class Self, class F>
  static void visit_fields(Self& s, F& f) {
    f("x", s.x, Extent::blocks);
    f("y", s.y, Extent::blocks);
    f("z", s.z, Extent::blocks);
    f("qw", s.qw, Extent::blocks);
    f("qx", s.qx, Extent::blocks);
    f("qy", s.qy, Extent::blocks);
    f("qz", s.qz, Extent::blocks);
    f("vx", s.vx, Extent::blocks);
    f("vy", s.vy, Extent::blocks);
    f("vz", s.vz, Extent::blocks);
    f("wx", s.wx, Extent::blocks);
    f("wy", s.wy, Extent::blocks);
    f("wz", s.wz, Extent::blocks);
    f("fx", s.fx, Extent::blocks);
    f("fy", s.fy, Extent::blocks);
    f("fz", s.fz, Extent::blocks);
    f("mx", s.mx, Extent::blocks);
    f("my", s.my, Extent::blocks);
    f("mz", s.mz, Extent::blocks);
    f("broken", s.broken, Extent::bonds);
    f("fs1", s.fs1, Extent::bonds);
    f("fs2", s.fs2, Extent::bonds);
    f("drive", s.drive, Extent::bonds);
    f("dt", s.dt, Extent::scalar);
    f("time", s.time, Extent::scalar);
    f("steps", s.steps, Extent::scalar);
    f("breakage", s.breakage, Extent::scalar);
    f("strain_for_log", s.strain_for_log, Extent::scalar);
    f("e_damping", s.e_damping, Extent::scalar);
    f("e_friction", s.e_friction, Extent::scalar);
    f("cracks", s.cracks, Extent::free);
  }
};

// The state's fields into a snapshot and back (the crack log as columns under "cracks/"); load_state throws
// std::invalid_argument when a field is missing, of another type or of the wrong length for a model of `blocks`
// blocks and `bonds` bonds.
void save_state(const ModelState<3>& state, Snapshot& snapshot);
void load_state(const Snapshot& snapshot, ModelState<3>& state, std::size_t blocks, std::size_t bonds);

}  // namespace rbdem
