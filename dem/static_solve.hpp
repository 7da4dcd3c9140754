// Static elastic solve of the intact bonded-block system (Eigen sparse), and the exact stability limit of the
// explicit scheme.
//
// Before any bond breaks the model is piecewise linear: each bond is a parallel bond (normal, shear, rotation
// springs kb_n A, kb_s A, kb_n I) plus the linear part, which acts only in compression ((k_n, k_s) A). Platens are
// the same half-plane contacts the explicit run uses (normal stiffness k_p t L on the boundary edges), frictionless
// unless loading.platen_friction > 0 (then the edges stick). With 3 dof per block (u_x, u_y, theta), the
// stiffness of bond b is K_b = B^T (K_N n n^T + K_S t t^T) B + K_R g g^T, where B maps the dofs of the two
// blocks to the relative displacement at the bond point and g picks theta_j - theta_i.
// The linear part of each bond is open (centre in tension), sticking, or sliding (|F_s| = mu F_n); under a
// proportional load every state keeps its ratio F_s/F_n, so a bond slides from the start or never, and the states
// are found by an active-set iteration (a few solves; a linear part that has changed state twice keeps its state,
// which ends the cycles of a few dozen bonds near the open/closed boundary). Sliding makes the matrix
// non-symmetric; it is a small perturbation of the symmetric part, so one sparse LDLT of the first (all closed,
// sticking) state preconditions BiCGSTAB for the later states (static_solve.cpp); about 0.2 s for the 40k dofs of
// the 1 mm paper specimen.
#pragma once

#include <atomic>
#include <vector>

#include "dem/engine.hpp"

namespace rbdem {

struct StaticResult {
  double platen_displacement = 0;   // m, imposed closure of the top platen
  double top_force = 0, bottom_force = 0;  // N, compression positive
  double apparent_modulus = 0;      // Pa: (F / (W t)) / (displacement / H)
  std::vector<double> ux, uy, rotation;  // per block, m and rad
  std::vector<double> fn_b, fs_b, m_b;   // per bond: parallel bond force and moment (compression positive)
  std::vector<double> fs_lin;            // per bond: linear part shear force (stick: elastic; slip: -+ mu F_n)
  std::vector<double> platen_fs;         // per block: platen shear force (sticking platens; 0 if frictionless)
  enum LinearState : std::uint8_t { open = 0, stick = 1, slip_positive = 2, slip_negative = 3 };
  std::vector<std::uint8_t> linear_state;  // per bond
  std::size_t open_bonds = 0, sliding_bonds = 0;
  // Linear parts held in their state after changing it twice (an active-set cycle near the open/closed boundary),
  // summed over the iterations in which they would have changed again.
  std::size_t held_bonds = 0;
  int active_set_iterations = 0;
  int krylov_iterations = 0;        // BiCGSTAB iterations over all active-set iterations
  int direct_fallbacks = 0;         // solves that fell back to sparse LU (BiCGSTAB did not converge)
  std::size_t dofs = 0;
  double seconds = 0;
  // Load factor at which the first bond reaches its strength (1 = this displacement), and that bond.
  double first_break_factor = 0;
  int first_break_bond = -1;
};

struct StaticOptions {
  double platen_displacement = 1e-6;  // m
  bool linear_parts_always_closed = false;  // every linear part closed and sticking (no active-set iteration)
  int max_iterations = 30;
  double krylov_tolerance = 1e-10;  // relative residual of the BiCGSTAB solves (states with sliding linear parts)
  // External loads: the generalized force on each block (fx, fy, moment; N, N, N m), 3 entries per block, in the
  // reference configuration (e.g. a confining pressure, jacket_load()). Empty = none.
  std::vector<double> load;
  // false: no platens (a specimen held only by its loads, e.g. a disc under diametral forces); then `anchors` name
  // blocks whose three dofs get a weak spring against the rigid-body modes (the loads must have no resultant).
  bool platens = true;
  std::vector<int> anchors;
  // Threads for BiCGSTAB's products with the stiffness, read at each solve (null: one). The results do not depend
  // on it. A run sets it to its threads once the stability limit beside the static start is done.
  const std::atomic<int>* threads = nullptr;
};

// Static solve for the engine's current (reference) configuration; uses its bonds, materials and platens.
StaticResult solve_static(const Engine& engine, const StaticOptions& options = {});

// The generalized load of a pressure p (Pa) on the engine's jacket edges (every outer edge not on a platen) in
// the reference configuration: F = -p t L n at each edge's midpoint, 3 entries per block.
std::vector<double> jacket_load(const Engine& engine, double pressure);

// a x fa + b x fb, field by field (displacements, rotations, bond forces, linear-part and platen shear, platen
// forces and displacement): two solutions of the same linear problem superpose when their linear-part states agree.
StaticResult superpose(const StaticResult& a, double fa, const StaticResult& b, double fb);

// The smallest lambda >= 0 at which some bond reaches its strength along the affine path base + lambda x increment
// (ParallelBond's test: dem/laws/parallel_bond.hpp), and that bond; +inf when none does.
double first_break_along(const Engine& engine, const StaticResult& base, const StaticResult& increment, int* bond = nullptr);

// Puts the engine into base + lambda x increment, with the velocity field of the increment's platen closing at
// `velocity` (base is static: an isotropic state reached before the axial loading). The engine's clock is set to
// the time the platen needs for lambda x increment.
void apply_static_path(Engine& engine, const StaticResult& base, const StaticResult& increment, double lambda,
                       double velocity);

// Puts the engine into the static state scaled by `factor` (displacements, rotations, the top platen, the linear
// parts' and platens' shear history), with the quasi-static velocity field of a platen closing at `velocity`.
// The engine's clock is set to the time the platen needs to get there. Used to start failure runs just below the
// first bond failure instead of integrating the linear ramp.
void apply_static_state(Engine& engine, const StaticResult& state, double factor, double velocity);

// 2 / sqrt(lambda_max(M^-1 K)) of the intact system with every linear part closed (its stiffest state), by power
// iteration: the largest stable step of the undamped central difference scheme. On `threads` threads (0: those
// the engine may use now, Engine::threads()); the same limit to the last bit at any count.
double stability_limit(const Engine& engine, int iterations = 300, int threads = 0);

}  // namespace rbdem
