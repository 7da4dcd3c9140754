// The explicit RB-DEM engine: rigid triangular blocks (x, y, theta), linear parallel bonds on shared edges,
// polygon contacts after breakage and between blocks that were never neighbours, two rigid platens, central
// difference time integration with Cundall local damping. THEORY.md sections 4, 4b and 5.
//
// Data are structures of arrays (STYLE.md 1). One step runs stages with one job each (STYLE.md 3):
//   rotations -> bond forces (parallel, one slot per bond) -> breakage events -> broad phase (when needed)
//   -> contact forces -> platen forces -> per-block gather in fixed order + damping + integration.
// Forces are gathered per block over a CSR list in a fixed order, so results are bit-identical at any thread count.
#pragma once

#include <array>
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

// Thrown when the run blows up (NaN or runaway velocities): the step is too large or the scene unphysical.
class InstabilityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct EngineOptions {
  double damping = 0.7;          // Cundall local damping alpha
  double mass_scaling = 1.0;     // density multiplier
  double platen_velocity = 0.0;  // m/s, top platen moves down at this speed; bottom fixed
  double platen_friction = 0.0;  // Coulomb coefficient block-platen
  int threads = 0;               // 0 = all
  bool platens = true;           // false: free blocks (for unit tests)

  static EngineOptions from_scene(const Scene& scene);
};

struct Energies {
  double kinetic = 0;      // J
  double strain = 0;       // J, stored in bonds and contacts
  double damping = 0;      // J, dissipated by local damping (cumulative)
  double friction = 0;     // J, dissipated by sliding (cumulative, approximate)
  double work_platen = 0;  // J, work done by the platens (cumulative)
};

class Engine {
 public:
  Engine(const Topology& topo, const Scene& scene, const EngineOptions& options);

  // --- time step ---
  // Critical step of THEORY.md 5 from every block's actual translational and rotational stiffness.
  double critical_step() const;
  // The exact stability limit of the undamped linearised system, 2 / sqrt(lambda_max(M^-1 K)), by power
  // iteration on the intact bonded stiffness (all linear parts in compression). For checks and reports.
  double stability_limit(int iterations = 200) const;
  void set_dt(double dt) { dt_ = dt; }
  double dt() const { return dt_; }

  // --- stepping ---
  void step();
  void run(long steps) {
    for (long k = 0; k < steps; ++k) step();
  }

  // --- state (public arrays: plain data) ---
  struct Blocks {
    std::vector<double> x, y, theta, vx, vy, omega;
    std::vector<double> fx, fy, moment;          // total force of the last step (without damping)
    std::vector<double> mass, inertia;           // scaled by mass_scaling
    std::vector<double> cos_t, sin_t;
    std::vector<double> x0, y0;                  // reference centroid
    std::vector<double> radius, inradius;
    std::vector<std::array<double, 6>> shape;    // body-frame vertices
    std::vector<int> layer;
    std::vector<std::uint8_t> free_face;         // has a broken bond or a boundary edge
    std::vector<std::uint8_t> fixed;             // kinematically fixed (tests)
  } blocks;

  struct Bonds {
    std::vector<int> i, j;
    std::vector<double> rix, riy, rjx, rjy;      // lever arms, body frame
    std::vector<double> n0x, n0y;                // reference normal, i -> j
    std::vector<double> L, A, I;                 // edge length, area L t, inertia t L^3/12
    std::vector<double> kbnA, kbsA, kbnI;        // parallel bond stiffness, N/m, N/m, N m
    std::vector<LinearContact> linear;           // linear part (kn, ks per area, mu)
    std::vector<double> d;                       // centroid distance along the normal
    std::vector<BondKind> kind;
    std::vector<std::uint8_t> broken;
    // state and output of the last step
    std::vector<double> fs_lin;                  // linear part shear force (history)
    std::vector<double> fn_b, fs_b, m_b, fn_lin; // parallel bond force, moment; linear normal force
    std::vector<double> sfx, sfy, smi, smj;      // force on j, moments on i and j (the per-bond slot)
  } bonds;

  struct ContactPairs {
    std::vector<int> i, j, bond;                 // bond = -1 for pairs that were never neighbours
    std::vector<LinearContact> law;
    std::vector<double> fs, fn, chord;           // shear history; normal force and chord of the last step
    std::vector<std::uint64_t> key;              // (i << 32) | j, sorted
  } contacts;

  // Platens: top at y = top_y() moving down, bottom at y = bottom_y() fixed.
  double top_y() const { return top_y_; }
  double bottom_y() const { return bottom_y_; }
  double top_force() const { return top_force_; }        // N, compression positive
  double bottom_force() const { return bottom_force_; }  // N, compression positive
  double platen_displacement() const { return top_y0_ - top_y_; }
  void set_platen_velocity(double v) { options_.platen_velocity = v; }

  double time() const { return time_; }
  long steps() const { return steps_; }
  const std::vector<Crack>& cracks() const { return cracks_; }
  std::size_t intact_bonds() const { return active_.size(); }
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

 private:
  void update_rotations();
  void bond_forces();
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

  const Topology& topo_;
  EngineOptions options_;
  double thickness_, width_, height_;
  double dt_ = 0, time_ = 0;
  long steps_ = 0;
  bool breakage_ = true;

  std::array<BondStrength, 2> strength_;     // by BondKind
  std::array<LinearContact, 2> contact_law_;  // by kind, per-area stiffness set per pair from d
  std::array<double, 2> modulus_{}, kappa_{};
  std::vector<int> active_;                  // intact bonds
  std::vector<int> csr_offset_, csr_entry_;  // per block: 2 * bond + (1 if block is j)
  std::vector<std::vector<int>> thread_breaks_;
  std::vector<std::pair<int, BreakMode>> pending_breaks_;

  // contact accumulators (serial stages)
  std::vector<double> cfx_, cfy_, cm_;
  // broad phase
  double skin_ = 0;
  std::vector<double> ref_x_, ref_y_;        // positions at the last rebuild
  double ref_top_ = 0;
  bool rebuild_ = true;
  std::vector<int> top_candidates_, bottom_candidates_;
  std::vector<double> top_fs_, bottom_fs_;   // per block platen shear history
  std::vector<double> platen_kn_;            // per block platen stiffness per area
  double top_y_ = 0, bottom_y_ = 0, top_y0_ = 0;
  double top_force_ = 0, bottom_force_ = 0;
  // energies (cumulative parts)
  double e_damping_ = 0, e_friction_ = 0, e_work_ = 0, platen_energy_ = 0;

  std::vector<Crack> cracks_;
};

}  // namespace rbdem
