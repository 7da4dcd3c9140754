// The elastic gate: the DEM's static elastic response against Amadei's closed form (docs/theory.md, section 2) and the deal.II
// FE twin, over the joint dip beta = 0, 15, ..., 90 deg, before any failure run is trusted.
//
// For each beta the scene's specimen is meshed at that dip (everything else as in the scene) and
//   dem_static  = the DEM static apparent modulus (platen force / (W t)) / (platen displacement / H),
//   dem_gauge   = the same stress over the interior strain (affine fit away from the platens, dem_constants.hpp),
//   amadei      = 1 / S22(beta) with the DEM-measured constants (virtual tests at 0, 45, 90 deg),
//   fe          = deal.II FE, frictionless platens, DEM-measured constants, the same mesh,
//   fe_goodman  = the same with Goodman's constants (intact rock + joint stiffness from the bond parameters),
// and with `fields` the block displacements of the DEM next to the FE ones at the block centroids.
// The gate passes when max over beta |E_dem / amadei - 1| <= scene.elastic.tolerance, with E_dem the modulus
// named by ElasticGateOptions::measure (docs/elastic.md says which one and why).
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

// Which DEM modulus the gate compares with Amadei's.
enum class GateMeasure {
  platen,  // dem_static: platen force and platen displacement (includes the platen contacts and end rows)
  gauge,   // dem_gauge: platen stress over the interior strain (the material alone)
};

struct ElasticGateOptions {
  std::vector<double> betas = {0, 15, 30, 45, 60, 75, 90};  // deg; must contain 0, 45 and 90 for the fit
  std::vector<double> fit_betas = {0, 45, 90};              // deg, the virtual tests that give the constants
  double end_fraction = 0.15;  // -, blocks closer than this fraction of H to a platen are left out of the gauge
  GateMeasure measure = GateMeasure::gauge;
  bool fields = false;   // keep DEM and FE block displacements per angle
  bool with_fe = true;   // FE columns (needs the deal.II build; otherwise NaN)
  int threads = 0;       // angles solved concurrently; 0 = hardware threads
  std::function<void(const std::string&)> log;  // progress lines (optional)
};

// Block-centroid displacements of one angle (m), DEM and FE (DEM-measured constants), the rigid x translation
// removed from each (mean u_x = 0), in block (= mesh triangle) order.
struct AngleFields {
  std::vector<double> x, y, dem_ux, dem_uy, fe_ux, fe_uy;
};

struct ElasticAngle {
  double beta_deg = 0;
  double amadei = 0;          // Pa, 1 / S22 with the DEM-measured constants
  double amadei_goodman = 0;  // Pa, 1 / S22 with Goodman's constants
  double dem_static = 0;      // Pa, platen-based DEM static modulus
  double dem_gauge = 0;       // Pa, interior-gauge DEM static modulus
  double fe = std::numeric_limits<double>::quiet_NaN();          // Pa
  double fe_goodman = std::numeric_limits<double>::quiet_NaN();  // Pa
  double field_l2 = std::numeric_limits<double>::quiet_NaN();    // relative L2 |u_dem - u_fe| / |u_fe|
  VirtualTest test;           // the measurement behind dem_static and dem_gauge
  AngleFields fields;         // with ElasticGateOptions::fields
  double fe_seconds = 0;
  double deviation(GateMeasure m) const { return (m == GateMeasure::gauge ? dem_gauge : dem_static) / amadei - 1.0; }
};

struct GateVerdict {
  double tolerance = 0.05;
  bool passed = false;
  GateMeasure measure = GateMeasure::gauge;
  double max_deviation = 0;     // max over beta |E_dem / amadei - 1| of the gated measure
  double worst_beta_deg = 0;
  double max_deviation_static = 0, max_deviation_gauge = 0;  // both measures, for the record
  std::string reason;           // why it failed (empty when passed)
};

struct ElasticReport {
  theory::Plane plane = theory::Plane::strain;
  ComplianceFit dem;            // the DEM-measured constants and the fit residual
  std::vector<double> fit_betas;  // deg, the virtual tests behind them
  VirtualTest intact;           // the unjointed specimen's test
  theory::TIConstants intact_constants;
  GoodmanEstimate goodman;
  std::vector<ElasticAngle> angles;
  GateVerdict gate;
  bool fe_available = false;
  double mesh_size = 0;
  double seconds = 0, dem_seconds = 0, fe_seconds = 0;  // wall time: all, DEM stage (meshing + static), FE stage
};

// Runs the measurements and the gate for a scene (its joint_set.dip_deg is ignored: every beta is run).
// Throws SceneError when the scene cannot be gated (a user mesh: the dips cannot be re-meshed).
ElasticReport run_elastic_gate(const Scene& scene, const ElasticGateOptions& options = {});

// elastic.json: constants.{dem,goodman}, angles[], gate{tolerance, passed, ...}, timing, and the resolved scene.
nlohmann::json elastic_json(const ElasticReport& report, const Scene& scene);

// The readable table: one row per beta with the moduli and differences, the constants and the verdict.
std::string elastic_table(const ElasticReport& report);

const char* measure_name(GateMeasure m);

}  // namespace rbdem::compare
