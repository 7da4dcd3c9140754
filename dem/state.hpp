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
#include "dem/topology.hpp"

namespace rbdem {

struct Crack {
  double time = 0, strain = 0;   // s, axial strain when the bond broke
  double x = 0, y = 0;           // m, bond position when it broke
  int bond = -1;
  BondKind kind = BondKind::rock;
  BreakMode mode = BreakMode::tensile;
  double sigma = 0, tau = 0;     // Pa, the bond stresses that broke it
};

// Block-block contact pairs with their history, sorted by key = (i << 32) | j, i < j.
struct ContactPairs {
  std::vector<int> i, j, bond;                 // bond = -1 for pairs that were never neighbours; an intact bond
                                               // (only with skip_bonded_pairs = false) makes the pair exert no force
  std::vector<LinearContact> law;
  std::vector<double> fs, fn, chord;           // shear history (N); normal force (N) and chord (m) of the last step
  std::vector<std::uint64_t> key;
  std::size_t size() const { return key.size(); }
};

// Which index space a field's entries belong to (restore checks each against the model).
enum class Extent : std::uint8_t { blocks, bonds, contacts, eligible, free, scalar };

struct ModelState {
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
  double ref_top = 0;                          // top platen position then (m)
  bool rebuild = true;                         // the next step rebuilds the pair list

  // --- boundary state: the platens ---
  double top_y = 0;                            // m, top platen position (the bottom one is fixed at Model::ymin)
  double platen_velocity = 0;                  // m/s, closing speed of the top platen
  double top_force = 0, bottom_force = 0;      // N, compression positive, of the last step
  std::vector<int> top_candidates, bottom_candidates;
  std::vector<double> top_fs, bottom_fs;       // per block platen shear history (N)

  // --- boundary state: the confining pressure (the jacket) ---
  double confining_pressure = 0;               // Pa, on every outer edge that is not on a platen
  int jacket_lost = 0, jacket_lost_max = 0;    // jacket edges without pressure now / at most so far (blocks that
                                               // lost every bond and contact: the rule in dem/stages/jacket.cpp)

  // --- clock ---
  double dt = 0, time = 0;                     // s
  long steps = 0;
  bool breakage = true;                        // false: an elastic lattice (tests, stability checks)
  double strain_for_log = 0;                   // axial strain the driver reports with new cracks

  // --- energy accounts (cumulative, J) ---
  double e_damping = 0, e_friction = 0, e_work = 0;
  double e_work_jacket = 0;                    // J, work of the confining pressure
  double platen_energy = 0;                    // J, elastic energy in the platen contacts at the last step

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
    f("ref_top", s.ref_top, Extent::scalar, false);
    f("rebuild", s.rebuild, Extent::scalar, false);
    f("top_y", s.top_y, Extent::scalar, false);
    f("platen_velocity", s.platen_velocity, Extent::scalar, false);
    f("top_force", s.top_force, Extent::scalar, false);
    f("bottom_force", s.bottom_force, Extent::scalar, false);
    f("top_candidates", s.top_candidates, Extent::free, false);
    f("bottom_candidates", s.bottom_candidates, Extent::free, false);
    f("top_fs", s.top_fs, Extent::blocks, false);
    f("bottom_fs", s.bottom_fs, Extent::blocks, false);
    f("confining_pressure", s.confining_pressure, Extent::scalar, false);
    f("jacket_lost", s.jacket_lost, Extent::scalar, false);
    f("jacket_lost_max", s.jacket_lost_max, Extent::scalar, false);
    f("dt", s.dt, Extent::scalar, false);
    f("time", s.time, Extent::scalar, false);
    f("steps", s.steps, Extent::scalar, false);
    f("breakage", s.breakage, Extent::scalar, false);
    f("strain_for_log", s.strain_for_log, Extent::scalar, false);
    f("e_damping", s.e_damping, Extent::scalar, false);
    f("e_friction", s.e_friction, Extent::scalar, false);
    f("e_work", s.e_work, Extent::scalar, false);
    f("e_work_jacket", s.e_work_jacket, Extent::scalar, false);
    f("platen_energy", s.platen_energy, Extent::scalar, false);
    f("cracks", s.cracks, Extent::free, false);
  }
};

// Throws std::invalid_argument when `s` does not fit a model of `blocks` blocks and `bonds` bonds (another scene or
// mesh): every field's length against its extent, and every block or bond index it holds in range.
void check_state_fits(const ModelState& s, std::size_t blocks, std::size_t bonds);

}  // namespace rbdem
