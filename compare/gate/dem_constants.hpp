// The DEM as an elastic material: its transversely isotropic constants measured by static virtual tests, and
// Goodman's equivalent-continuum estimate from the scene's bond parameters (docs/theory.md, sections 2, 3, 5).
//
// Virtual test: the scene's specimen, meshed at one joint dip beta, between frictionless platens, solved by
// solve_static() (exact elastic state of the bonded blocks with the linear parts' open/stick/slip states). The
// stress is uniaxial and uniform: sigma_yy = -F / (W t) (tension positive), sigma_xx = tau_xy = 0. The strains come
// from a least-squares affine fit u = u0 + G x of the block centroid displacements over the interior (blocks at
// least end_fraction H from both platens), which keeps the platens' contact compliance and the end rows of
// blocks out of the measurement. Then S12 = eps_xx / sigma_yy, S22 = eps_yy / sigma_yy, S26 = gamma_xy / sigma_yy.
//
// Fit: S12, S22, S26 of theory::rotated_compliance(a, beta) are linear in the reduced compliance
// a = (a11, a22, a12, a66), so the tests (the gate uses all seven dips, 21 numbers) give a by weighted least
// squares, each test's three rows divided by its own |S22| (a relative fit: the stiff directions count as much as
// the soft ones, which keeps a11 determined when the joints are thousands of times softer than the rock), and
// theory::constants_from_compliance(a, plane) the five constants. The relative residual says how far the DEM is
// from a transversely isotropic continuum at the tested angles; the condition number how much a relative error of
// the data can grow in the constants.
//
// Goodman: intact rock E_r, nu_r from the same virtual test on the unjointed specimen; a joint bond replaces a
// rock bond in series, so the joint's extra compliance per area is
//   1/k_n = d_mean (1/(2 E*_j) - 1/(2 E*_r)),  1/k_s = d_mean (kappa_j/(2 E*_j) - kappa_r/(2 E*_r)),
// with d_mean the length-weighted mean centroid distance of the joint bonds and the factor 2 because the closed
// linear part and the parallel bond act in parallel in compression (2 E*/d per area). An estimate, not a test.
//
// Joint interfaces (the FE model with the joints, continuum/fe_joints.hpp): the same extra compliance per joint
// bond with that bond's own centroid distance d instead of d_mean, one interface per joint bond on its mesh edge.
// SI units (Pa, m, Pa/m), angles in degrees.
#pragma once

#include <cstddef>
#include <vector>

#include "theory/elasticity.hpp"
#include "dem/scene.hpp"
#include "dem/static_solve.hpp"
#include "dem/topology.hpp"

namespace rbdem::compare {

// Homogeneous strain of the interior from the block centroid displacements (engineering shear strain).
struct GaugeStrain {
  double eps_xx = 0, eps_yy = 0, gamma_xy = 0;
  double rotation = 0;   // rad, (du_y/dx - du_x/dy) / 2
  std::size_t blocks = 0;  // blocks in the fit
  double misfit = 0;     // rms of the fit residual / rms of the affine part (how far from homogeneous)
};

// Least-squares affine fit over the blocks whose centroid lies at least end_fraction x height from both platens.
GaugeStrain gauge_strain(const Topology<2>& topo, const std::vector<double>& ux, const std::vector<double>& uy,
                         double end_fraction);

// One static virtual uniaxial test.
struct VirtualTest {
  double beta_deg = 0;
  double platen_displacement = 0;  // m, imposed closure of the top platen
  double stress = 0;            // Pa, sigma_yy = -F / (W t): negative in compression
  double platen_modulus = 0;    // Pa, StaticResult::apparent_modulus: platen force over platen displacement / H
  double gauge_modulus = 0;     // Pa, sigma_yy / eps_yy of the interior gauge
  GaugeStrain gauge;
  double S12 = 0, S22 = 0, S26 = 0;  // 1/Pa, measured global compliance entries
  std::size_t blocks = 0, bonds = 0, joint_bonds = 0, open_bonds = 0, sliding_bonds = 0, dofs = 0;
  std::size_t open_joint_bonds = 0;  // of open_bonds, the joint bonds
  int active_set_iterations = 0;
  double solve_seconds = 0;
};

// The scene the elastic measurements use: the given one with frictionless platens (Amadei's formula and the
// FE patch test assume platens free to slide; platen friction is a loading condition, not a material property).
Scene elastic_test_scene(const Scene& scene);

// Runs the static solve on `topo` (built from the scene's mesh at dip beta_deg) and measures it. When `state` is
// given it receives the static solution (block displacements for field comparisons).
// linear_parts_closed: every linear part closed and sticking (a linear DEM; diagnostics).
VirtualTest virtual_test(const Topology<2>& topo, const Scene& scene, double beta_deg, double end_fraction,
                         StaticResult* state = nullptr, bool linear_parts_closed = false);

struct ComplianceFit {
  theory::ReducedCompliance a;
  theory::TIConstants constants;
  double residual = 0;      // rms of the 3 n residuals, each relative to its test's |S22|
  double max_residual = 0;  // largest of them
  // Condition number (2-norm) of the weighted system with each unknown scaled by its own size (a11, a22, a66 by
  // themselves, a12 by sqrt(a11 a22)): the factor by which a relative error of the data can grow in the constants.
  double condition = 0;
  std::size_t tests = 0;    // virtual tests in the fit
  bool admissible = false;  // the constants give a positive definite compliance
};

// Weighted least squares over every test's S12, S22, S26, each test's rows divided by its |S22| (needs tests at
// three or more distinct angles, e.g. 0, 45, 90).
ComplianceFit fit_compliance(const std::vector<VirtualTest>& tests, theory::Plane plane);

// E and nu of an isotropic specimen from one test: a11 = a22 = S22, a12 = S12, a66 = 2 (a11 - a12).
theory::TIConstants isotropic_constants(const VirtualTest& test, theory::Plane plane);

struct JointBondStats {
  double sum_length = 0, sum_length_d = 0;  // m, m^2
  std::size_t count = 0;
  void add(const Topology<2>& topo);
  void merge(const JointBondStats& o) {
    sum_length += o.sum_length, sum_length_d += o.sum_length_d, count += o.count;
  }
  double mean_d() const { return sum_length > 0 ? sum_length_d / sum_length : 0.0; }  // length-weighted, m
};

struct GoodmanEstimate {
  double E_r = 0, nu_r = 0;      // Pa, -: intact rock (virtual test on the unjointed specimen)
  double k_n = 0, k_s = 0;       // Pa/m, joint stiffness per area (infinite without joints)
  double spacing = 0;            // m
  double d_mean = 0;             // m, length-weighted mean centroid distance of the joint bonds
  theory::TIConstants constants;
};

GoodmanEstimate goodman_estimate(const Scene& scene, const theory::TIConstants& intact, double d_mean);

// The extra compliance per area and per unit centroid distance of a joint bond over the rock bond it replaces
// (1/Pa): c_n = 1/(2 E*_j) - 1/(2 E*_r), c_s = kappa_j/(2 E*_j) - kappa_r/(2 E*_r). A bond of centroid distance d
// adds d c_n, d c_s (m/Pa) in series; c <= 0 means a joint not softer than the rock in that direction.
// Open: the joint bond's linear part open (its centre in tension), the parallel bond alone against a closed rock
// bond: c_n_open = 1/E*_j - 1/(2 E*_r), c_s_open = kappa_j/E*_j - kappa_r/(2 E*_r).
struct JointCompliance {
  double c_n = 0, c_s = 0;
  double c_n_open = 0, c_s_open = 0;
};
JointCompliance joint_compliance(const Scene& scene);
// The same for the joint material `joint` (joint or joint2) against scene.rock.
JointCompliance joint_compliance(const Scene& scene, const MaterialParams& joint);
// The same for a joint bond between blocks of the rocks r1 and r2 (rock or rock2), a fraction f1 of its centroid
// distance d in r1's block: the rock bond it replaces has the compliance f1/(2 E*_1) + (1 - f1)/(2 E*_2) per area
// and unit d (kappa/(2 E*) each in shear). With r1 and r2 the same object: joint_compliance(scene, joint).
JointCompliance joint_compliance(const MaterialParams& joint, const MaterialParams& r1, const MaterialParams& r2,
                                 double f1);

// One joint bond as an interface of the FE model with the joints: its mesh edge, centroid distance and length, and
// k_n = 1 / (d c_n), k_s = 1 / (d c_s) (Pa/m). A direction whose compliance is not positive is rigid: both
// directions rigid = glued (k = +inf, tied copies); one direction rigid = a penalty k = 1e4 E_r / d in it (1e-4 of
// the compliance of one rock bond layer), counted in `stiffened`.
// k_n_open, k_s_open: the same with the open compliance (the linear part open), for the unilateral joints.
struct JointInterface {
  int node_a = 0, node_b = 0;  // mesh nodes
  double d = 0, length = 0;    // m
  double k_n = 0, k_s = 0;     // Pa/m (+inf when glued)
  double k_n_open = 0, k_s_open = 0;  // Pa/m (+inf when glued)
  bool glued = false;
};

struct JointInterfaces {
  std::vector<JointInterface> edges;  // in the topology's bond order
  std::size_t glued = 0;      // edges with both directions rigid
  std::size_t stiffened = 0;  // edges with one direction rigid (penalty)
  double sum_length = 0;      // m, over all edges
  double sum_length_compliance_n = 0, sum_length_compliance_s = 0;  // sum L / k (m^2/Pa) over the finite directions
  void merge(const JointInterfaces& o);
  // Length-weighted harmonic means (Pa/m): 1 / (mean compliance); +inf when every edge is glued or none exists.
  double mean_k_n() const;
  double mean_k_s() const;
};

// The joint bonds of `topo` (kind == joint) as interfaces; intact_E: the rock's E for the penalty.
JointInterfaces joint_interfaces(const Topology<2>& topo, const Scene& scene, double intact_E);

}  // namespace rbdem::compare
