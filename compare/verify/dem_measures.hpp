// The DEM's closed-form experiments as plain measurements, shared by `rbdem verify` (compare/verify/cases_dem.cpp,
// cases_3d.cpp, which add the tolerances and their sources) and the unit tests (tests/test_engine.cpp,
// tests/test_static.cpp, tests/test_rigid3.cpp).
#pragma once

#include <cstddef>

#include "dem/static_solve.hpp"
#include "dem/vec3.hpp"

namespace rbdem::verify {

// A rigid rotation by 1 rad and a translation (0.3, -0.2) m of a bonded 5 mm-mesh specimen, one step.
struct RigidMotionMeasure {
  double max_force = 0;        // N (and N m / L for the moment): the largest bond force of any kind
  double spurious_strain = 0;  // max over bonds of |force| / (E* L t)
  std::size_t blocks = 0, bonds = 0, cracks = 0;
};
RigidMotionMeasure rigid_motion_forces();

// Block 1 of the rhombus (verify::rhombus(1 mm, 0.8 mm)) oscillates against the fixed block 0, preloaded into
// compression so that the linear part stays closed. Expected period 2 pi sqrt(m / k), k = 2 E* L t / d.
// Throws std::runtime_error when fewer than ten periods are found.
struct PairPeriodMeasure {
  double period = 0, expected = 0;  // s, from ten upward zero crossings
  double max_sideways = 0;          // m, |x| of block 1 at the end (symmetry: 0)
  long steps = 0;
};
PairPeriodMeasure bonded_pair_period(double steps_per_period);

// Two facing unbonded triangles (verify::facing_triangles(1 mm)) meet at 1 m/s, head on or at angle_deg, without
// friction or damping; dt = 0.02 sqrt(m / k).
struct ImpactMeasure {
  double energy_ratio = 0;  // kinetic energy after / before
  long steps = 0;
  bool touched = false, separated = false;
};
ImpactMeasure frictionless_impact(double angle_deg);

// A softening bond (docs/model.md, "Softening bonds") of the rhombus verify::rhombus(a, 0.8 a), sigma_c = c =
// 7.5 MPa, phi_b = 40 deg, E* = 160 GPa, kappa = 1.5, pulled open (or slid, `shear`) quasi-statically: block 1 is
// moved along the bond's normal (tangent) in steps of 1/200 of the elastic limit, and the bond force integrated
// over the displacement until the bond breaks.
struct SofteningPullMeasure {
  double energy_per_area = 0;  // J/m^2 dissipated until the break
  double peak_stress = 0;      // Pa, the largest traction carried
  double break_opening = 0;    // m, displacement at the break
  bool broke = false;
  long steps = 0;
};
SofteningPullMeasure softening_pull(double a, double fracture_energy, bool shear);

// The static solve and an explicit UCS run from rest (no elastic start, unbreakable bonds, 4 mm mesh, 2e-4
// strain) of the paper specimen at dip beta; the explicit modulus is the slope over 30-100 % of the strain.
struct SlopeMeasure {
  StaticResult static_state;
  double explicit_modulus = 0;  // Pa
  std::size_t curve_points = 0, cracks = 0, blocks = 0;
  long steps = 0;
};
SlopeMeasure static_and_explicit_moduli(double beta_deg, bool slip_when_bonded);

// A torque-free asymmetric block, principal moments (1, 2, 3) kg m^2 turned from the world's axes, spinning at
// `omega_body` (rad/s, in its principal frame), stepped `steps` times at dt by the 3D rigid step without damping.
struct TorqueFreeMeasure {
  double momentum_drift = 0;  // max over the steps of |L - L0| / |L0|
  double energy_spread = 0;   // (max - min) / E0 of the kinetic energy over the steps
  double energy_drift = 0;    // |E_end - E0| / E0
  double unit_error = 0;      // max over the steps of ||q| - 1|
};
TorqueFreeMeasure torque_free_run(Vec3 omega_body, double dt, long steps);

}  // namespace rbdem::verify
