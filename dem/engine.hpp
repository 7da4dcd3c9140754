// The explicit RB-DEM engine: rigid triangular blocks (x, y, theta), linear parallel bonds on shared edges,
// polygon contacts after breakage and between blocks that were never neighbours, two rigid platens, central
// difference time integration with Cundall local damping. THEORY.md sections 4, 4b and 5; docs/model.md.
//
// Data are plain arrays (STYLE.md 1). What the bond loop reads together is packed together: a block's kinematic
// state is one 64-byte record (BlockState), a bond's constant frame another (BondFrame), and each bond writes its
// forces into its own slot (BondSlot). One step runs stages with one job each (STYLE.md 3):
//   bond forces (parallel, one slot per bond) -> breakage events -> broad phase (when needed)
//   -> contact forces (parallel, one record per pair, summed in pair order) -> platen forces
//   -> per-block gather in fixed order + damping + integration.
// Forces are gathered per block over a CSR list in a fixed order, so results are bit-identical at any thread count.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/contact_law.hpp"
#include "dem/scene.hpp"
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

// Thrown when the run blows up (positions no longer finite): the step is too large or the scene unphysical.
class InstabilityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct EngineOptions {
  double damping = 0.7;          // Cundall local damping alpha
  double mass_scaling = 1.0;     // density multiplier
  double platen_velocity = 0.0;  // m/s, top platen moves down at this speed; bottom fixed
  double platen_friction = 0.0;  // Coulomb coefficient block-platen
  int threads = 0;               // 0 = all; the most the run may use
  // When set, each step uses min(*thread_budget, threads) threads (at least one): a sweep hands the cores of its
  // idle workers to the runs still going. Results do not depend on the thread count (engine.hpp header).
  const std::atomic<int>* thread_budget = nullptr;
  bool platens = true;           // false: free blocks (unit tests)
  bool contacts = true;          // false: no block-block contacts (diagnostics)
  bool skip_bonded_pairs = true;       // numerics.skip_bonded_pairs: no narrow phase for intact-bonded pairs
  bool search_free_faces_only = true;  // numerics.search_free_faces_only: broad phase over free-face blocks only

  static EngineOptions from_scene(const Scene& scene);
};

struct Energies {
  double kinetic = 0;      // J
  double strain = 0;       // J, stored in bonds, contacts and platen contacts
  double damping = 0;      // J, dissipated by local damping (cumulative)
  double friction = 0;     // J, dissipated by sliding contacts (cumulative, approximate)
  double work_platen = 0;  // J, work done by the top platen (cumulative)
};

// Kinematic state of one block, one cache line.
struct BlockState {
  double x, y, theta;        // centroid (m) and rotation (rad)
  double vx, vy, omega;      // velocities (m/s, rad/s) at the half step
  double cos_t, sin_t;       // of theta
};

// Constant data of one bond, one cache line: lever arms from each centroid to the edge midpoint and the
// reference normal (i -> j) in the blocks' reference frames, the edge length, and k A = (E*/d) L t, the normal
// stiffness of the parallel bond and of the linear part. Everything else derives from these and the bond kind:
// A = L t, I = t L^3/12, kb_s A = k A / kappa, kb_n I = k A L^2/12.
struct BondFrame {
  double rix, riy, rjx, rjy;
  double n0x, n0y;
  double L;
  double kA;  // N/m
};

// Forces a bond writes each step: force on block j (on i the opposite) and the moments on i and j.
struct BondSlot {
  double fx, fy, mi, mj;
};

// The forces of one bond in its co-rotated frame (diagnostics, static comparisons, energies).
struct BondForces {
  double fn_b = 0, fs_b = 0, m_b = 0;  // parallel bond: normal (compression positive), shear, moment on j
  double fn_lin = 0, fs_lin = 0;       // linear part
  double sigma = 0, tau = 0;           // parallel bond peripheral stresses (tension positive)
};

struct BondStiffness {
  double kbnA, kbsA, kbnI;  // parallel bond: N/m, N/m, N m
  double knA, ksA, mu;      // linear part (closed edge): N/m, N/m, -
  bool slip_bonded;         // the linear part slides while the bond is intact
  double A, I, L;           // m^2, m^4, m
};

class Engine {
 public:
  Engine(const Topology& topo, const Scene& scene, const EngineOptions& options);

  // --- time step ---
  // Critical step estimate of THEORY.md 5 from every block's own translational and rotational stiffness,
  // min over blocks of sqrt(m / k_trans) and sqrt(I / k_rot). About half the exact limit of the lattice
  // (stability_limit() in static_solve.hpp), which the UCS driver uses.
  double critical_step() const;
  void set_dt(double dt) { dt_ = dt; }
  double dt() const { return dt_; }

  // --- stepping ---
  void step();
  void run(long steps) {
    for (long k = 0; k < steps; ++k) step();
  }

  // --- state (plain data) ---
  struct Blocks {
    std::vector<BlockState> state;
    std::vector<double> fx, fy, moment;          // total force of the last step (without damping)
    std::vector<double> mass, inertia;           // scaled by mass_scaling
    std::vector<double> x0, y0;                  // reference centroid
    std::vector<double> radius, inradius;
    std::vector<std::array<double, 6>> shape;    // body-frame vertices
    std::vector<int> layer;
    std::vector<std::uint8_t> free_face;         // has a broken bond or a boundary edge
    std::vector<std::uint8_t> fixed;             // kinematically fixed (tests)
    std::vector<double> ext_fx, ext_fy, ext_m;   // external loads (N, N m)
    std::size_t size() const { return state.size(); }
  } blocks;

  struct Bonds {
    std::vector<int> i, j;
    std::vector<BondFrame> frame;
    std::vector<BondKind> kind;
    std::vector<std::uint8_t> broken;
    std::vector<double> fs_lin;                  // linear part shear force (history), N
    std::vector<double> drive;                   // softening bonds: 0 below the strength, then the largest
                                                 // failure index reached (1 = strength)
    std::vector<BondSlot> slot;
    std::size_t size() const { return i.size(); }
  } bonds;

  struct ContactPairs {
    std::vector<int> i, j, bond;                 // bond = -1 for pairs that were never neighbours; an intact bond
                                                 // (only with skip_bonded_pairs = false) makes the pair exert no force
    std::vector<LinearContact> law;
    std::vector<double> fs, fn, chord;           // shear history; normal force and chord of the last step
    std::vector<std::uint64_t> key;              // (i << 32) | j, sorted
  } contacts;

  // --- force evaluation without stepping (reference integrators, compare/reference_integrator.hpp) ---
  // The generalized force (F_x, F_y, M) on every block at the current positions and velocities, without advancing
  // time, the state or any history: every intact bond through the same bond law as step() with its stored linear-
  // part shear force (dt = 0), plus the external loads, gathered in step()'s fixed CSR order. Contacts and platens
  // are left out (their shear carries history that only step() advances), so this is the whole force only for an
  // engine built with platens = false and contacts = false. It refreshes the cached cos/sin of theta and overwrites
  // the bond slots, both of which step() recomputes before reading: results of step() are unchanged.
  void bonded_forces(std::vector<double>& fx, std::vector<double>& fy, std::vector<double>& moment);
  bool has_contacts() const { return options_.contacts; }

  BondStiffness stiffness(int bond) const;
  // The forces of a bond in the current state (without advancing its shear history).
  BondForces bond_forces(int bond) const;

  // Platens: top at y = top_y() moving down, bottom at y = bottom_y() fixed.
  double top_y() const { return top_y_; }
  double bottom_y() const { return bottom_y_; }
  double top_force() const { return top_force_; }        // N, compression positive
  double bottom_force() const { return bottom_force_; }  // N, compression positive
  double platen_displacement() const { return top_y0_ - top_y_; }
  void set_platen_velocity(double v) { options_.platen_velocity = v; }
  void set_platen_displacement(double d) { top_y_ = top_y0_ - d; }
  // Shear history of a block's platen contact (the platen it touches is found from its position).
  void set_platen_shear(int block, double fs);
  void set_time(double t) { time_ = t; }

  double time() const { return time_; }
  long steps() const { return steps_; }
  const std::vector<Crack>& cracks() const { return cracks_; }
  std::size_t intact_bonds() const { return active_.size() + softened_.size(); }
  std::size_t active_contacts() const;
  Energies energies() const;
  double specimen_height() const { return height_; }
  double specimen_width() const { return width_; }
  double thickness() const { return thickness_; }

  // Breakage on or off (off: elastic lattice, for tests and the stability check).
  void set_breakage(bool on) { breakage_ = on; }
  // Called for each new crack (after it is logged).
  std::function<void(const Crack&)> on_crack;
  // Current axial strain reported with cracks (the driver sets it).
  double strain_for_log = 0.0;

  // Rebuild internal lists after the caller changed positions or bond states directly (tests, elastic start).
  void refresh();

  // Model data the static solver and writers read.
  const Topology& topology() const { return topo_; }
  const BondStrength& strength(BondKind k) const { return kinds_[int(k)].strength; }
  double platen_stiffness(int block) const { return platen_kn_[std::size_t(block)]; }  // Pa/m
  double platen_friction() const { return options_.platen_friction; }
  bool has_platens() const { return options_.platens; }
  double kappa(BondKind k) const { return kinds_[int(k)].kappa; }

  // The complete mutable state of a run: everything step() reads that the scene and topology do not determine
  // (checkpoints). Restoring a snapshot into an engine built from the same scene and topology continues the run
  // bit for bit as if it had never stopped, at any thread count.
  struct Snapshot {
    std::vector<BlockState> state;
    std::vector<double> fx, fy, moment;
    std::vector<std::uint8_t> free_face, broken;
    std::vector<double> fs_lin, drive;
    std::vector<BondSlot> slot;
    ContactPairs contacts;
    std::vector<Crack> cracks;
    double dt = 0, time = 0, platen_velocity = 0, strain_for_log = 0;
    long steps = 0;
    bool breakage = true, rebuild = true;
    double top_y = 0, top_force = 0, bottom_force = 0, ref_top = 0;
    double e_damping = 0, e_friction = 0, e_work = 0, platen_energy = 0;
    std::vector<int> eligible, top_candidates, bottom_candidates;
    std::vector<double> ref_x, ref_y, top_fs, bottom_fs;
  };
  Snapshot snapshot() const;
  // Throws std::invalid_argument when the snapshot's sizes do not fit this engine (another scene or mesh).
  void restore(const Snapshot& s);

  // Per-kind parameters (rock = 0, joint = 1).
  struct KindParams {
    double modulus = 0, kappa = 1, inv_kappa = 1, mu = 0;
    bool slip_bonded = false;  // the linear part of an intact bond slides at mu F_n
    double inertia_divisor = 12.0;       // I = t L^3 / inertia_divisor (12; dem/fault_injection.hpp)
    double inertia_factor = 1.0 / 12.0;  // its inverse, for the per-step kernel
    BondStrength strength;
    // Softening (docs/model.md, "Softening bonds"): a bond of edge L and stiffness kA breaks at failure index
    // r_u = softening kA / L, with softening = 2 G_f / (sigma_c^2 t); 0 = brittle (r_u = 1).
    double softening = 0;
  };
  // The fraction of its elastic forces that bond b still carries (1 - damage; 1 for brittle bonds).
  double intact_fraction(int b) const;

 private:
  void update_rotations();
  void compute_bond_forces();
  template <bool Softened>
  void bond_loop(const std::vector<int>& list, std::vector<Crack>& breaks, int& onsets);
  void process_breaks();
  void broad_phase();
  void contact_forces();
  void platen_forces();
  void integrate();
  void rebuild_active();
  bool needs_rebuild() const;
  void block_vertices(int b, double* out) const;
  std::uint64_t pair_key(int i, int j) const { return (std::uint64_t(std::uint32_t(i)) << 32) | std::uint32_t(j); }
  bool bonded(int i, int j) const;
  // The threads of the next parallel stage. With a budget every stage reads it, so that no team is ever larger
  // than the cores the sweep gave the run (idle extra threads make libgomp stop spinning and wake slowly).
  int threads() const {
    return options_.thread_budget ? std::clamp(options_.thread_budget->load(std::memory_order_relaxed), 1, nthreads_)
                                  : nthreads_;
  }

  const Topology& topo_;
  EngineOptions options_;
  double thickness_, width_, height_;
  double dt_ = 0, time_ = 0;
  long steps_ = 0;
  bool breakage_ = true;

  std::array<KindParams, 2> kinds_;
  std::vector<int> active_;                  // intact bonds that have not started to soften
  std::vector<int> softened_;                // intact softening bonds past their strength (drive > 0)
  std::vector<int> csr_offset_, csr_entry_;  // per block: 2 * bond + (1 if block is j)
  std::vector<std::vector<Crack>> thread_breaks_;  // one list per thread the run may use
  std::vector<int> thread_onsets_;                 // bonds that started to soften, per thread
  int nthreads_ = 1;                               // the most threads the run may use

  // contact accumulators (serial stages)
  std::vector<double> cfx_, cfy_, cm_;
  // per contact pair, written in parallel and gathered in pair order: force on j, moments on i and j, friction work
  struct PairForce {
    double fx, fy, mi, mj, friction;
  };
  std::vector<PairForce> pair_force_;
  // broad phase
  double skin_ = 0;
  std::vector<int> eligible_;                // blocks with a free face at the last rebuild
  std::vector<double> ref_x_, ref_y_;        // their positions at the last rebuild
  double ref_top_ = 0;
  bool rebuild_ = true;
  std::vector<int> top_candidates_, bottom_candidates_;
  std::vector<double> top_fs_, bottom_fs_;   // per block platen shear history
  std::vector<double> platen_kn_;            // per block platen stiffness per area
  std::vector<double> platen_lref_;          // per block platen L_ref
  double top_y_ = 0, bottom_y_ = 0, top_y0_ = 0;
  double top_force_ = 0, bottom_force_ = 0;
  // energies (cumulative parts)
  double e_damping_ = 0, e_friction_ = 0, e_work_ = 0, platen_energy_ = 0;

  std::vector<Crack> cracks_;
};

}  // namespace rbdem
