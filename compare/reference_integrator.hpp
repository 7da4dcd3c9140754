// Reference time integration of the bonded-block equations of motion with SUNDIALS ARKODE, and the engine's own
// central difference run between synchronous states so the two can be compared (docs/reference_integrator.md).
//
// The undamped equations of motion of the engine's rigid blocks, a first-order system with six unknowns per block,
//     d/dt (x, y, theta)   = (vx, vy, omega)                              m, rad, m/s, rad/s
//     d/dt (vx, vy, omega) = (F_x / m, F_y / m, M / I)                    F from Engine::evaluate_forces
// use the engine's own force evaluation for the right-hand side: the same stages as a step (bonds, block-block
// contacts, platens, external loads), without advancing any history. Three integrators:
//   integrate_explicit   ERKStep, adaptive explicit Runge-Kutta (Fehlberg 13-stage order 8 by default) at tight
//                        tolerance: the reference solution.
//   integrate_implicit   ARKStep with a diagonally implicit Runge-Kutta table, Newton iterations, a dense or banded
//                        direct linear solver and SUNDIALS' difference-quotient Jacobian: the path for stiff cases.
//   central_difference   Engine::step() with damping 0 (a leapfrog with half-step velocities), started with a half
//                        kick v(-dt/2) = v(0) - dt/2 a(x(0)) and closed with v(T) = v(T - dt/2) + dt/2 a(x(T)), which
//                        makes it velocity Verlet: positions and velocities of all three are taken at the same time.
//
// Scope (check_reference_scope throws otherwise): damping 0, breakage off (engine.set_breakage(false): a break is an
// event, not part of the ODE), and no shear history anywhere: frictionless platens, and contact_friction 0 with
// slip_when_bonded for rock and joint, which clamps the shear of every linear part and contact to zero. Platens
// (the top one moving at its velocity: the right-hand side depends on t) and block-block contacts, including those
// of broken bonds, are inside the scope. Fixed blocks (Engine::fix_block) stay where they are.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "dem/simulation_impl.hpp"
#include "dem/scene.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// A state vector: for block b, entries 6b .. 6b+5 are x, y, theta, vx, vy, omega (m, m, rad, m/s, m/s, rad/s).
using BlockStateVector = std::vector<double>;

BlockStateVector get_state(const Engine<2>& engine);
// Sets positions and velocities and refreshes the engine's derived data (cos/sin of theta).
void set_state(Engine<2>& engine, const BlockStateVector& y);

// Throws std::invalid_argument naming the setting to change when the engine is outside the scope above.
void check_reference_scope(const Engine<2>& engine, double damping);

// Error tolerances: relative rtol on every entry, absolute atol per kind of entry.
struct Tolerances {
  double rtol = 1e-12;
  std::array<double, 6> atol{1e-20, 1e-20, 1e-18, 1e-16, 1e-16, 1e-14};  // x, y, theta, vx, vy, omega

  // atol = rtol x the typical size of each entry: displacement u (m), velocity v (m/s), block size l (m).
  static Tolerances scaled(double rtol, double u, double v, double l);
};

struct IntegrationStats {
  long steps = 0;            // accepted steps
  long attempts = 0;         // accepted + rejected
  long rhs_evals = 0;        // force evaluations (including those of the difference-quotient Jacobian)
  long newton_iters = 0;     // implicit only
  long jacobian_evals = 0;   // implicit only
  double wall_seconds = 0;
  double cpu_seconds = 0;    // of this thread: the fairer figure on a shared machine (all runs are serial)
};

struct IntegrationResult {
  BlockStateVector state;    // at t_end
  IntegrationStats stats;
};

enum class ExplicitTable { fehlberg_13_7_8, verner_8_5_6, dormand_prince_7_4_5 };

// Explicit adaptive Runge-Kutta from y0 at t = 0 to t_end (hit exactly, no interpolation).
IntegrationResult integrate_explicit(Engine<2>& engine, const BlockStateVector& y0, double t_end, const Tolerances& tol,
                                     ExplicitTable table = ExplicitTable::fehlberg_13_7_8);

enum class ImplicitTable { sdirk_5_3_4, kvaerno_7_4_5, trbdf2_3_3_2 };
enum class LinearSolver { dense, band };

struct ImplicitOptions {
  ImplicitTable table = ImplicitTable::sdirk_5_3_4;
  // band: blocks are numbered along the longer side of the specimen so the Jacobian is banded; the band's
  // half-width follows from the bonds. dense: the full 6n x 6n matrix.
  LinearSolver solver = LinearSolver::band;
};

// Implicit adaptive DIRK (ARKStep) from y0 at t = 0 to t_end.
IntegrationResult integrate_implicit(Engine<2>& engine, const BlockStateVector& y0, double t_end, const Tolerances& tol,
                                     const ImplicitOptions& options = {});

// The engine's own central difference (step() with the engine's options) over `steps` steps of dt from the
// synchronous state y0, returning the synchronous state at steps x dt (see the header comment).
IntegrationResult central_difference(Engine<2>& engine, const BlockStateVector& y0, double dt, long steps);

// Relative errors of `y` against `ref` at the same time, with y0 the common start: the root mean square over blocks
// of the position difference (x, y and radius x theta) divided by that of the reference's displacement from y0;
// likewise for velocities (v and radius x omega) against the reference's velocities.
struct StateError {
  double position = 0, velocity = 0;
};
StateError state_error(const Engine<2>& engine, const BlockStateVector& y, const BlockStateVector& ref,
                       const BlockStateVector& y0);

// --- the small specimen of the reference studies (tests/test_reference.cpp, benchmarks/bench_reference.cpp) ---

enum class InitialField {
  smooth,       // u_y = -strain (y - ymin), v_x = velocity sin(pi (y - ymin) / 2H): low modes of the whole specimen
  layer_rigid,  // no displacement; each layer moves rigidly with v_x = velocity sin(pi (y_layer - ymin) / 2H), layers
                // holding a fixed block stay at rest: the slow sliding of layers on soft joints
};

struct ReferenceSpecimen {
  double width = 0.01, height = 0.005;  // m
  double mesh_size = 0.0015;            // m
  double dip_deg = 30.0, spacing = 0.003;
  double joint_contrast = 1.0;         // rock effective modulus / joint effective modulus (joint = rock / contrast)
  InitialField field = InitialField::smooth;
  double strain = 1e-5;                // -, amplitude of the initial displacement
  double velocity = 0.02;              // m/s, amplitude of the initial velocity
  bool platens = false;                // frictionless platens; the top one starts on the displaced specimen top
  double platen_velocity = 0.0;        // m/s, closing speed of the top platen
  bool break_joints = false;           // every joint bond broken: the layers meet through clipped contacts
};

// The scene, topology, an engine in the reference scope (bottom row of blocks fixed, damping 0, breakage off, one
// thread) and the initial state. Joint modulus = rock modulus / joint_contrast, both history-free in shear.
struct ReferenceProblem {
  ReferenceSpecimen specimen;
  Scene scene;
  std::unique_ptr<Topology<2>> topology;
  std::unique_ptr<SimulationImpl<2>> sim;  // its engine is the problem's (Engine<2>: sim->engine())
  BlockStateVector y0;
  double stability_limit = 0;              // s, of the undamped central difference (stability_limit())
  // A fresh simulation of the same topology, its engine in the reference scope (each integrator run gets its own).
  std::unique_ptr<SimulationImpl<2>> make_simulation() const;
  Engine<2>& engine() const { return sim->engine(); }
};
ReferenceProblem make_reference_problem(const ReferenceSpecimen& specimen);

}  // namespace rbdem
