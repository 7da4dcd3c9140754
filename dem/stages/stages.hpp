// The stages of one explicit step, each with one job (docs/architecture.md):
//   rotations    cos and sin of every block's rotation                       (integrator.cpp)
//   bonds        every intact bond's parallel bond and linear part -> one force slot per bond, and the bonds whose
//                failure test held                                           (bonds.cpp)
//   bond events  softening and breakage in bond order, the crack log         (bonds.cpp)
//   detection    the broad phase: candidate pairs among free-face blocks     (contacts.cpp)
//   contacts     narrow phase and the linear contact law per pair            (contacts.cpp)
//   boundaries   the platens (platens.cpp) and the confining pressure on the jacket (jacket.cpp)
//   integrator   per-block gather in a fixed order, local damping, central difference (integrator.cpp)
// Every stage reads the constant Model, reads or writes the ModelState and the engine's Workspace, and runs on at
// most `threads` OpenMP threads. Each bond and each contact pair writes into its own slot; the per-block gather
// sums them in a fixed order, so results are bit-identical at any thread count.
//
// A force evaluation either advances time (`advance`: the shear histories move on by dt, energies are booked, the
// failure test runs) or only evaluates the forces at the current state (the reference integrators,
// compare/reference_integrator.hpp): one code path serves both.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace rbdem {

// What the step derives from the state and writes before it reads: never part of a snapshot.
struct Workspace {
  std::vector<double> cos_t, sin_t;                   // of each block's theta
  // Per bond, the forces it applies: on j (on i the opposite) and the moments on i and j. One record per bond (the
  // gather reads a bond's record whole, and a vectorised kernel stores it whole).
  struct Slot {
    double fx, fy, mi, mj;
  };
  std::vector<Slot> slot;
  std::vector<double> keep;                           // per bond: fraction of its elastic forces it carries;
                                                      // -1 for a broken bond (the kernel's "alive" test)
  std::size_t damaged = 0;                            // intact bonds past their strength (softening)
  std::vector<int> flag;                              // per bond: the failure test held this step
  std::vector<std::vector<int>> flagged;              // per thread: bonds whose failure test held, in bond order
  std::vector<double> cfx, cfy, cm;                   // per block: contact and boundary forces of this step
  struct PairForce {
    double fx, fy, mi, mj, friction;                  // force on j, moments on i and j, friction work
  };
  std::vector<PairForce> pair_force;                  // per contact pair
  std::vector<double> ext_fx, ext_fy, ext_m;          // per block: constant external loads (tests)
  std::vector<std::uint8_t> touching;                 // per block: in a contact that carries force (the jacket)
};

struct StepContext {
  double dt = 0;        // s; 0 when only evaluating
  bool advance = true;  // advance histories and book energies
  int threads = 1;
};

namespace stages {

// cos and sin of every block's rotation.
void update_rotations(const ModelState& s, Workspace& w, int threads);

// The bond stage: slots of every bond (zero for broken ones) and, when advancing with breakage on, the bonds whose
// failure test held in w.flagged.
void bond_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c);
// Bond events in bond order: softening bonds advance their damage, bonds past their strength break (slot zeroed,
// free faces marked, the pair's contact takes over the linear shear force, crack logged, on_crack called).
// Returns the number of bonds that broke.
int bond_events(const Model& m, ModelState& s, Workspace& w, const std::function<void(const Crack&)>& on_crack);
// The damage factor of every bond from its drive (after a restore or an edit).
void refresh_keep(const Model& m, const ModelState& s, Workspace& w);

struct DetectionOptions {
  bool contacts = true;                // block-block contacts at all
  bool platens = true;
  bool skip_bonded_pairs = true;       // no narrow phase for pairs joined by an intact bond
  bool search_free_faces_only = true;  // broad phase over free-face blocks only
};
// The broad phase, when a block or the platen moved half a skin since the last rebuild or a bond broke.
void detect_contacts(const Model& m, ModelState& s, const DetectionOptions& o, int threads);
// Narrow phase and contact law per pair, summed in pair order into w.cfx, w.cfy, w.cm (which it first zeroes).
void contact_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c);
// The two platens: half-plane contacts of the candidate blocks, added to w.cfx, w.cfy, w.cm.
void platen_forces(const Model& m, ModelState& s, Workspace& w, double platen_friction, bool platens,
                   const StepContext& c);
// The confining pressure on the jacket edges (follower forces), added to w.cfx, w.cfy, w.cm; after contact_forces.
void jacket_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c);
// Gather in fixed CSR order, Cundall local damping alpha, central difference. Throws InstabilityError when a
// position becomes non-finite.
void integrate(const Model& m, ModelState& s, Workspace& w, double damping, int threads);
// The total generalized force on every block without damping (the same gather as integrate()).
void gather_forces(const Model& m, const ModelState& s, const Workspace& w, std::vector<double>& fx,
                   std::vector<double>& fy, std::vector<double>& moment);

// The vertices of block b at its current position (x0, y0, x1, y1, x2, y2).
void block_vertices(const Model& m, const ModelState& s, const Workspace& w, int b, double* out);

}  // namespace stages
}  // namespace rbdem
