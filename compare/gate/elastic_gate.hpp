// The elastic gate: the DEM's static elastic response against the FE model with the joints as interfaces (the
// comparison that decides), Amadei's closed form (docs/theory.md, section 2) and the homogenized deal.II FE twin,
// over the joint dip beta = 0, 15, ..., 90 deg, before any failure run is trusted.
//
// For each beta the scene's specimen is meshed at that dip (everything else as in the scene) and
//   dem_static  = the DEM static apparent modulus (platen force / (W t)) / (platen displacement / H),
//   dem_gauge   = the same stress over the interior strain (affine fit away from the platens, dem_constants.hpp),
//   fe_joints   = continuum::solve_elastic_jointed on the same mesh: every layer the DEM's intact rock (constants
//                 measured on the unjointed specimen), every joint bond an interface with that bond's extra
//                 compliance (dem_constants.hpp, joint_interfaces), unilateral as the DEM's joint bonds (an
//                 interface whose sides separate takes the compliance of the bond without its linear part),
//                 frictionless platens; measured with the same gauge at the block centroids (fe_joints_platen:
//                 from the platens),
//   amadei      = 1 / S22(beta) with the DEM-measured constants (virtual tests at every dip, weighted fit),
//   fe          = deal.II FE, frictionless platens, DEM-measured constants, the same mesh,
//   fe_goodman  = the same with Goodman's constants (intact rock + joint stiffness from the bond parameters),
// and with `fields` the block displacements of the DEM next to both FE ones at the block centroids.
// The gate passes when max over beta |dem_gauge / fe_joints - 1| <= scene.elastic.tolerance: both model the same
// discrete structure, so this holds whether or not the layers homogenize. Amadei's comparison is reported beside
// it, with an indicator of whether homogenization applies (Homogenization); it decides only in a build without
// deal.II, where the FE model with the joints does not exist. docs/elastic.md says which and why.
// Plain data in and out; the command line prints and writes (apps/cmd_elastic.cpp).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/gate/dem_constants.hpp"
#include "theory/elasticity.hpp"
#include "dem/scene.hpp"

namespace rbdem::compare {

// Which DEM modulus the gate compares (with the FE model with the joints measured the same way, and with Amadei).
enum class GateMeasure {
  platen,  // dem_static: platen force and platen displacement (includes the platen contacts and end rows)
  gauge,   // dem_gauge: platen stress over the interior strain (the material alone)
};

struct ElasticGateOptions {
  std::vector<double> betas = {0, 15, 30, 45, 60, 75, 90};      // deg
  std::vector<double> fit_betas = {0, 15, 30, 45, 60, 75, 90};  // deg, the virtual tests that give the constants
  double end_fraction = 0.15;  // -, blocks closer than this fraction of H to a platen are left out of the gauge
  GateMeasure measure = GateMeasure::gauge;
  bool fields = false;   // keep the DEM's and both FE models' block displacements per angle
  bool with_fe = true;   // FE columns (needs the deal.II build; otherwise NaN)
  // The rock of the layers in the FE model with the joints: measured on each dip's own mesh with the joint bonds
  // given the rock's bond parameters (same_mesh), or the unjointed specimen's constants at every dip (intact).
  enum class LayerRock { same_mesh, intact };
  LayerRock layer_rock = LayerRock::same_mesh;
  // When the DEM misses the FE model with the joints, repeat both with every linear part closed and sticking (a
  // linear DEM) to tell the opening of linear parts in tension (which a linear FE model cannot represent) from a DEM
  // fault. It decides only where no linear part slides (Coulomb sliding is not excused).
  bool linear_check = true;
  // The FE model with the joints: uniform refinement levels of each DEM triangle (continuum::JointedFeOptions::
  // refinement; constant strain triangles are too stiff in bending) for the comparisons with the DEM, and UMFPACK up
  // to joints_direct_dof_limit DoFs (CG+AMG above: soft joints slow CG down).
  int joints_refinement = 1;
  std::size_t joints_direct_dof_limit = 200000;
  int threads = 0;       // angles solved concurrently; 0 = hardware threads
  std::function<void(const std::string&)> log;  // progress lines (optional)
};

// Block-centroid displacements of one angle (m): DEM, FE (DEM-measured constants) and the FE model with the joints,
// the rigid x translation removed from each (mean u_x = 0), in block (= mesh triangle) order.
struct AngleFields {
  std::vector<double> x, y, dem_ux, dem_uy, fe_ux, fe_uy, fe_joints_ux, fe_joints_uy;
};

struct ElasticAngle {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  double beta_deg = 0;
  double amadei = 0;          // Pa, 1 / S22 with the DEM-measured constants
  double amadei_goodman = 0;  // Pa, 1 / S22 with Goodman's constants
  double dem_static = 0;      // Pa, platen-based DEM static modulus
  double dem_gauge = 0;       // Pa, interior-gauge DEM static modulus
  double fe = nan;            // Pa, homogenized FE with the DEM-measured constants
  double fe_goodman = nan;    // Pa, homogenized FE with Goodman's constants
  double field_l2 = nan;      // relative L2 |u_dem - u_fe| / |u_fe|
  // The FE model with the joints (NaN without deal.II): layers of rock_constants, joint_interfaces() of this mesh.
  double fe_joints = nan;          // Pa, interior gauge at the block centroids (as dem_gauge)
  double fe_joints_platen = nan;   // Pa, from the platens (as dem_static)
  double field_l2_joints = nan;    // relative L2 |u_dem - u_fej| / |u_fej|
  GaugeStrain fe_joints_gauge;     // the gauge on the FE block-centroid displacements
  // Its unilateral joints (as the DEM's joint bonds, whose linear part takes no tension): the joint edges open at
  // the end of the active-set iteration, its solves, and whether it settled.
  std::size_t fe_joints_open_edges = 0;
  int fe_joints_state_solves = 0;
  bool fe_joints_states_settled = true;
  // The rock of the layers: the virtual test of this dip's mesh with rock bonds on the joints, and the isotropic
  // constants from it (E, nu from S22, S12), or the intact constants (ElasticGateOptions::LayerRock).
  VirtualTest rock_test;
  theory::TIConstants rock_constants;
  // With rock2 layers (rock2.groups or beds.pattern), the same for rock2: the FE model with the joints gives each
  // layer the constants of its rock.
  VirtualTest rock2_test;
  theory::TIConstants rock2_constants;
  // Beds of two rocks (beds.pattern): Salamon's interbedded medium (theory::interbedded: Backus' average of the two
  // rocks of the layers at the pattern's thickness fractions, with this dip's mean joint stiffness), Amadei's 1/S22.
  double interbedded = nan;  // Pa
  // Homogenization measured: the FE model with the joints with the intact rock (platen modulus) against Goodman's
  // homogenized modulus with the same rock and this dip's mean interface stiffness (closed form, = homogenized FE).
  // With beds of two rocks both use the intact constants of each rock and Salamon's medium.
  double fe_joints_intact_platen = nan;  // Pa
  double homogenized = nan;              // Pa
  // The linear check (ElasticGateOptions::linear_check, run only when the DEM misses fe_joints): the DEM and the FE
  // model with the joints again, every linear part closed and sticking (DEM, and the rock test of the layers).
  double dem_linear = nan;         // Pa, the gated measure (dem_gauge or dem_static)
  double fe_joints_linear = nan;   // Pa, the same measure
  std::size_t interface_edges = 0, glued_edges = 0, stiffened_edges = 0, fe_joints_dofs = 0;
  double fe_joints_seconds = 0;  // the FE model with the joints at this dip (both rocks)
  VirtualTest test;              // the measurement behind dem_static and dem_gauge
  AngleFields fields;            // with ElasticGateOptions::fields
  double fe_seconds = 0;         // the two homogenized FE solves
  double deviation(GateMeasure m) const { return (m == GateMeasure::gauge ? dem_gauge : dem_static) / amadei - 1.0; }
  // The DEM against the FE model with the joints, each measured the same way.
  double deviation_joints(GateMeasure m) const {
    return m == GateMeasure::gauge ? dem_gauge / fe_joints - 1.0 : dem_static / fe_joints_platen - 1.0;
  }
  double homogenization_error() const { return fe_joints_intact_platen / homogenized - 1.0; }
};

// Whether Amadei's (and Goodman's) homogenized continuum describes the specimen. Homogenized moduli assume a
// uniform stress. Joints much softer than the rock make the stress follow the stiff layers instead, near the free
// sides and, when few layers fit across, everywhere. Indicator: the joint compliance over one spacing relative to the
// rock's, compliance_ratio = (1/k_n) / (s / E_r), over the layers across the width, W / s:
//   indicator = compliance_ratio / (W / s) = E_r / (k_n W)
// (the joints' compliance over the specimen width relative to the rock's). Homogenization applies when
// indicator <= homogenization_max_indicator (docs/elastic.md: the threshold and the measurements behind it).
// measured_error is its measured counterpart, max over beta |ElasticAngle::homogenization_error()|.
struct Homogenization {
  double layers_across = 0;     // W / s
  std::size_t joints_held = 0;  // most joints one specimen holds over the dips (layers - 1)
  double contrast = 0;          // E*_rock / E*_joint of the bonds
  double compliance_ratio = 0;  // (1/k_n) / (s / E_r), k_n the mean of the interfaces, E_r the intact E
  double indicator = 0;         // compliance_ratio / layers_across
  double max_indicator = 0;     // the threshold
  double measured_error = std::numeric_limits<double>::quiet_NaN();
  bool applies = false;
  std::string outside;          // why Goodman's one-set homogenization is not the model at all (two sets, rock
                                // bridges, two rocks); empty when it is
};

// Amadei's curve with the DEM-measured constants beside the verdict: a fair comparison when homogenization applies
// and the DEM is one TI continuum (the seven-dip fit leaves a small residual).
struct AmadeiCheck {
  bool applicable = false;
  double max_residual_for_ti = 0.01;  // fit residual above which the DEM is not one TI continuum
  double max_deviation = 0;           // max over beta |E_dem / amadei - 1| of the gated measure
  double worst_beta_deg = 0;
  std::string note;                   // why (not) applicable
};

struct GateVerdict {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  double tolerance = 0.05;
  bool passed = false;
  GateMeasure measure = GateMeasure::gauge;
  // What decided: "fe_joints" (the DEM against the FE model with the joints), "fe_joints_linear" (the same with
  // every linear part closed, when the DEM as it runs misses only through linear parts opening in tension), or
  // "amadei" (no FE model with the joints: a build without deal.II).
  std::string comparison = "fe_joints";
  double max_deviation = 0;     // max over beta of the deciding comparison, |E_dem / E_ref - 1|
  double worst_beta_deg = 0;
  double max_deviation_static = 0, max_deviation_gauge = 0;  // against Amadei, both measures, for the record
  double max_deviation_joints = nan;         // max |dem_gauge / fe_joints - 1|
  double max_deviation_joints_platen = nan;  // max |dem_static / fe_joints_platen - 1|
  double worst_beta_joints_deg = 0;          // where max_deviation_joints is
  double max_deviation_linear = nan;         // max |dem_linear / fe_joints_linear - 1| (linear check)
  std::string message;          // one line: the verdict, which comparison decided and why, Amadei beside it
  std::string reason;           // why it failed and what to do (empty when passed)
};

// The interfaces of the FE model with the joints, over the seven meshes.
struct InterfaceSummary {
  double k_n = 0, k_s = 0;        // Pa/m, length-weighted harmonic means (+inf: all glued)
  double c_n = 0, c_s = 0;        // 1/Pa, joint_compliance(): extra compliance per area per unit d
  std::size_t edges = 0, glued = 0, stiffened = 0;  // interface edges, glued ones, one direction rigid
  std::string note;               // says when joints are glued (not softer than the rock) or stiffened
};

struct ElasticReport {
  theory::Plane plane = theory::Plane::strain;
  ComplianceFit dem;            // the DEM-measured constants, the fit residual and condition number
  std::vector<double> fit_betas;  // deg, the virtual tests behind them
  VirtualTest intact;           // the unjointed specimen's test
  theory::TIConstants intact_constants;
  bool two_rocks = false;                 // layers of rock2 (rock2.groups or beds.pattern)
  theory::TIConstants intact2_constants;  // rock2 on the unjointed specimen (two_rocks)
  GoodmanEstimate goodman;
  InterfaceSummary interfaces;
  Homogenization homogenization;
  AmadeiCheck amadei;
  std::vector<ElasticAngle> angles;
  GateVerdict gate;
  bool fe_available = false;
  bool linear_check_run = false;      // the linear check ran (the DEM missed fe_joints)
  bool linear_check_sliding = false;  // linear parts slide at a dip that missed (then the check cannot decide)
  double mesh_size = 0;
  double width = 0, height = 0;  // m, the specimen
  // Wall time: all, DEM stage (meshing and static solves, with the rock tests of the layers), FE stage (homogenized
  // and with the joints), the linear check; fe_joints_seconds is the sum of the per-dip times of the FE model with
  // the joints (they overlap on threads).
  double seconds = 0, dem_seconds = 0, fe_seconds = 0, linear_check_seconds = 0, fe_joints_seconds = 0;
};

// Runs the measurements and the gate for a scene (its joint_set.dip_deg is ignored: every beta is run).
// Throws SceneError when the scene cannot be gated (a user mesh: the dips cannot be re-meshed).
ElasticReport run_elastic_gate(const Scene& scene, const ElasticGateOptions& options = {});

// elastic.json: constants.{dem,goodman}, angles[], gate{tolerance, passed, ...}, timing, and the resolved scene.
nlohmann::json elastic_json(const ElasticReport& report, const Scene& scene);

// The readable table: one row per beta with the moduli and differences, the constants and the verdict.
std::string elastic_table(const ElasticReport& report);

// The threshold of Homogenization::indicator (docs/elastic.md, "When homogenization applies").
constexpr double homogenization_max_indicator = 0.05;

const char* measure_name(GateMeasure m);

}  // namespace rbdem::compare
