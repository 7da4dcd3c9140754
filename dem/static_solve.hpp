// Static elastic solve of the intact bonded-block system of the 2D model (Eigen sparse), and the exact stability
// limit of the explicit scheme. SimulationImpl<2> (dem/simulation_impl.hpp) offers them through the Simulation
// interface; the options and the result are dimension-free (dem/static_result.hpp).
//
// Before any bond breaks the model is piecewise linear: each bond is a parallel bond (normal, shear, rotation
// springs kb_n A, kb_s A, kb_n I) plus the linear part, which acts only in compression ((k_n, k_s) A). The boundary
// components attached to the engine add their rows (dem/boundary/hooks.hpp): the platens are the same half-plane
// contacts the explicit run uses (normal stiffness k_p t L on the boundary edges), frictionless unless their
// friction is above 0 (then the edges stick); fixed block groups hold their blocks' dofs at zero; force groups add
// their loads. With 3 dof per block (u_x, u_y, theta), the stiffness of bond b is
// K_b = B^T (K_N n n^T + K_S t t^T) B + K_R g g^T, where B maps the dofs of the two blocks to the relative
// displacement at the bond point and g picks theta_j - theta_i.
// The linear part of each bond is open (centre in tension), sticking, or sliding (|F_s| = mu F_n), the law's
// linearised form (BondStiffness, dem/model.hpp); under a proportional load every state keeps its ratio F_s/F_n, so
// a bond slides from the start or never, and the states are found by an active-set iteration (a few solves; a
// linear part that has changed state twice keeps its state, which ends the cycles of a few dozen bonds near the
// open/closed boundary). Sliding makes the matrix non-symmetric; it is a small perturbation of the symmetric part,
// so one sparse LDLT of the first (all closed, sticking) state preconditions BiCGSTAB for the later states
// (dem/sparse_solve.hpp); about 0.2 s for the 40k dofs of the 1 mm paper specimen.
#pragma once

#include "dem/engine.hpp"
#include "dem/static_result.hpp"

namespace rbdem {

// Static solve for the engine's current (reference) configuration; uses its bonds, materials and components.
StaticResult solve_static(const Engine<2>& engine, const StaticOptions& options = {});

// The smallest lambda >= 0 at which some bond reaches its strength along the affine path base + lambda x increment
// (ParallelBond's test: dem/laws/parallel_bond.hpp), and that bond; +inf when none does.
double first_break_along(const Engine<2>& engine, const StaticResult& base, const StaticResult& increment,
                         int* bond = nullptr);

// Every bond's own factor along the same path (+inf for a broken bond or one that never breaks), in bond order; with
// `mean_strength` each bond at its material's stated strength, without its Weibull factor (the same factors without
// heterogeneity). An empty base is the unloaded specimen.
std::vector<double> break_factors_along(const Engine<2>& engine, const StaticResult& base,
                                        const StaticResult& increment, bool mean_strength);

// Puts the engine into base + lambda x increment, with the velocity field of the increment's platen closing at
// `velocity` (base is static: an isotropic state reached before the axial loading). The engine's clock is set to
// the time the platen needs for lambda x increment; the components take their part of the state.
void apply_static_path(Engine<2>& engine, const StaticResult& base, const StaticResult& increment, double lambda,
                       double velocity);

// Puts the engine into the static state scaled by `factor` (displacements, rotations, the linear parts' shear
// history; the components: the top platen, the platens' shear history), with the quasi-static velocity field of a
// platen closing at `velocity`. The engine's clock is set to the time the platen needs to get there. Used to start
// failure runs just below the first bond failure instead of integrating the linear ramp.
void apply_static_state(Engine<2>& engine, const StaticResult& state, double factor, double velocity);

// 2 / sqrt(lambda_max(M^-1 K)) of the intact system with every linear part closed (its stiffest state) and the
// attached components, by power iteration: the largest stable step of the undamped central difference scheme. On
// `threads` threads (0: those the engine may use now, Engine::threads()); the same limit to the last bit at any
// count.
double stability_limit(const Engine<2>& engine, int iterations = 300, int threads = 0);

}  // namespace rbdem
