// ModelState: the complete mutable state of a DEM model, and nothing else. It is the snapshot: restoring it into
// an engine built from the same scene and topology continues a run bit for bit as if it had never stopped, at any
// thread count. Checkpoints (io/checkpoint.hpp), restore's size checks and the reference integrator's state vector
// all walk one field table, ModelState::fields(): adding a state field touches that table and nothing else.
//
// Plain arrays, structure of arrays: the block kinematics are six arrays (x, y, theta, vx, vy, omega), so the
// bond kernel gathers exactly the fields it reads and the integrator streams them. What the step derives from the
// state (cos and sin of theta, per-bond force slots, the damage factors of softened bonds, the force
// accumulators) lives in the engine's workspace and is recomputed, never stored.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "dem/laws/linear_contact.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/records.hpp"
#include "dem/snapshot.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// Block-block contact pairs with their history, sorted by key = (i << 32) | j, i < j.
struct ContactPairs {
  std::vector<int> i, j, bond;                 // bond = -1 for pairs that were never neighbours; an intact bond
                                               // (only with skip_bonded_pairs = false) makes the pair exert no force
  std::vector<LinearContact> law;
  std::vector<double> fs, fn, chord;           // shear history (N); normal force (N) and chord (m) of the last step
  std::vector<double> opening_x, opening_y;    // dilation history (m): the opening LinearContact's sliding built
                                               // up, along the normal from i to j (0 for a flat law)
  std::vector<std::uint64_t> key;
  std::size_t size() const { return key.size(); }
};

template <int dim>
struct ModelState;

template <>
struct ModelState<2> {
  // --- blocks: kinematic state, centroid (m), rotation (rad), velocities at the half step (m/s, rad/s) ---
  std::vector<double> x, y, theta, vx, vy, omega;
  std::vector<double> fx, fy, moment;          // total force of the last step without damping (N, N m)
  std::vector<std::uint8_t> free_face;         // has a broken bond or a boundary edge

  // --- bond history ---
  std::vector<std::uint8_t> broken;
  std::vector<double> fs_lin;                  // linear part shear force (N)
  std::vector<double> drive;                   // softening bonds: 0 below the strength, then the largest failure
                                               // index reached (1 = strength)

  // --- contact history and detection ---
  ContactPairs contacts;
  std::vector<int> eligible;                   // blocks with a free face at the last broad-phase rebuild
  std::vector<double> ref_x, ref_y;            // their positions then (m)
  bool rebuild = true;                         // the next step rebuilds the pair list

  // --- clock ---
  double dt = 0, time = 0;                     // s
  long steps = 0;
  bool breakage = true;                        // false: an elastic lattice (tests, stability checks)
  double strain_for_log = 0;                   // axial strain the driver reports with new cracks

  // --- energy accounts (cumulative, J) ---
  double e_damping = 0, e_friction = 0;

  std::vector<Crack> cracks;                   // the crack log, in order of breakage

  std::size_t num_blocks() const { return x.size(); }

  // The field table: calls f(name, field, extent, kinematic) for every field above, in a fixed order. `field` is a
  // reference to a std::vector<T> (T: double, int, std::uint8_t) or a scalar (double, long, int, bool); the contact
  // pairs and the crack log are visited as their own types (ContactPairs, std::vector<Crack>). `kinematic` marks
  // the six block arrays the reference integrator evolves. Both the const and the mutable visits use this list.
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
    f("x", s.x, Extent::blocks, true);
    f("y", s.y, Extent::blocks, true);
    f("theta", s.theta, Extent::blocks, true);
    f("vx", s.vx, Extent::blocks, true);
    f("vy", s.vy, Extent::blocks, true);
    f("omega", s.omega, Extent::blocks, true);
    f("fx", s.fx, Extent::blocks, false);
    f("fy", s.fy, Extent::blocks, false);
    f("moment", s.moment, Extent::blocks, false);
    f("free_face", s.free_face, Extent::blocks, false);
    f("broken", s.broken, Extent::bonds, false);
    f("fs_lin", s.fs_lin, Extent::bonds, false);
    f("drive", s.drive, Extent::bonds, false);
    f("contacts", s.contacts, Extent::contacts, false);
    f("eligible", s.eligible, Extent::eligible, false);
    f("ref_x", s.ref_x, Extent::eligible, false);
    f("ref_y", s.ref_y, Extent::eligible, false);
    f("rebuild", s.rebuild, Extent::scalar, false);
    f("dt", s.dt, Extent::scalar, false);
    f("time", s.time, Extent::scalar, false);
    f("steps", s.steps, Extent::scalar, false);
    f("breakage", s.breakage, Extent::scalar, false);
    f("strain_for_log", s.strain_for_log, Extent::scalar, false);
    f("e_damping", s.e_damping, Extent::scalar, false);
    f("e_friction", s.e_friction, Extent::scalar, false);
    f("cracks", s.cracks, Extent::free, false);
  }
};

// Throws std::invalid_argument when `s` does not fit a model of `blocks` blocks and `bonds` bonds (another scene or
// mesh): every field's length against its extent, and every block or bond index it holds in range.
void check_state_fits(const ModelState<2>& s, std::size_t blocks, std::size_t bonds);

// The state's fields into a snapshot, walking the field table (the contact pairs and the crack log as columns under
// "contacts/" and "cracks/"), and back. load_state throws std::invalid_argument when a field is missing or of
// another type; the sizes are check_state_fits'.
void save_state(const ModelState<2>& state, Snapshot& snapshot);
void load_state(const Snapshot& snapshot, ModelState<2>& state);

}  // namespace rbdem
