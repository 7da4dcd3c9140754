// The elastic gate in 3D: the DEM's static elastic response of the scene's cylinder or prism against the FE twin on
// the same tetrahedra with the DEM's own constants (the comparison that decides), Amadei's 3D closed form and the FE
// twin with Goodman's constants, over the dip beta = 0, 15, ..., 90 deg at the scene's dip direction.
//
// The DEM's five constants E, nu, E', nu', G' come from virtual tests on prisms (dem_constants3.hpp); Goodman's from
// the unjointed prism's E, nu and the joint bonds' extra compliance. For each beta the scene's specimen is meshed
// at that dip and
//   dem_static = the static solve of the face-bond network (dem/static3.hpp), <sigma_zz> / -eps_zz with the strain
//                fitted to the blocks' centroid displacements (the body's own modulus, free of the platen
//                contacts; dem_platen: the platens' reading),
//   fe         = the FE twin (continuum/fe_3d.hpp) with the DEM's constants, its mean-strain modulus (fe_platen:
//                the platens' reading),
//   fe_goodman = the same with Goodman's constants,
//   amadei     = Amadei's 1 / S'_33 with the DEM's constants (amadei_goodman: with Goodman's;
//                amadei_goodman_fabric: with Goodman's from the jointed mesh's rock, dem_constants3.hpp),
// and the apparent Poisson's ratios along the joints' strike and dip direction of each. The gate passes when
// max over beta |dem_static / fe - 1| <= elastic.tolerance; without the FE module (a build without deal.II) Amadei
// with the DEM's constants decides. Beside them, fe_joints: the FE twin with the joints as interfaces
// (continuum/fe_joints3.hpp) in the jointed mesh's rock, each joint face of its own bond's extra compliance; it is
// reported, not gated (it is 1-4 % stiffer than the network, docs/elastic.md, "Three dimensions").
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/gate/dem_constants3.hpp"
#include "dem/scene.hpp"

namespace rbdem::compare {

struct Elastic3Options {
  std::vector<double> betas = {0, 15, 30, 45, 60, 75, 90};  // deg
  bool with_fe = true;  // the FE columns (the deal.II module); off or unavailable: NaN, and Amadei decides
  // Solves side by side (the virtual tests, then the dips): 0 = the hardware's threads. Meshing stays serial (gmsh
  // holds one global model); each solve is independent, so no number depends on the count.
  int threads = 0;
  std::function<void(const std::string&)> log;  // progress lines (optional)
};

struct Elastic3Angle {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  double beta_deg = 0;
  double amadei = 0, amadei_goodman = 0;  // Pa
  double amadei_goodman_fabric = nan;     // Pa, Amadei with Goodman's constants on the jointed mesh's rock
  double dem_static = 0, dem_platen = 0;  // Pa
  double fe = nan, fe_platen = nan, fe_goodman = nan;  // Pa
  // Pa: the FE twin with the joints as interfaces (the jointed mesh's rock, each joint face the DEM's compliance)
  double fe_joints = nan, fe_joints_platen = nan;
  double fe_joints_poisson_strike = nan, fe_joints_poisson_dip = nan;
  // Apparent Poisson's ratios -eps_lateral / eps_zz along the strike and the horizontal dip direction.
  double dem_poisson_strike = 0, dem_poisson_dip = 0;
  double amadei_poisson_strike = 0, amadei_poisson_dip = 0;
  double fe_poisson_strike = nan, fe_poisson_dip = nan;
  std::size_t blocks = 0, bonds = 0, joint_bonds = 0, dofs = 0, fe_dofs = 0;
  double mesh_seconds = 0, dem_seconds = 0, fe_seconds = 0, fe_joints_seconds = 0;
  double deviation_fe() const { return dem_static / fe - 1.0; }
  double deviation_amadei() const { return dem_static / amadei - 1.0; }
};

struct Gate3Verdict {
  double tolerance = 0.05;
  bool passed = false;
  std::string comparison = "fe";  // "fe" (the FE twin with the DEM's constants) or "amadei" (no FE module)
  double max_deviation = 0;       // max over beta of the deciding comparison, |dem_static / ref - 1|
  double worst_beta_deg = 0;
  double max_deviation_amadei = 0;  // max |dem_static / amadei - 1|, for the record
  std::string message, reason;      // the verdict in one line; why it failed and what to do (empty when passed)
};

struct Elastic3Report {
  DemConstants3 constants;
  std::vector<Elastic3Angle> angles;
  Gate3Verdict gate;
  bool fe_available = false;
  std::string shape;                  // "cylinder" or "prism"
  double mesh_size = 0, dip_direction_deg = 0;
  // Wall time: all; the constants' virtual tests (wall); meshing, DEM solves and FE solves summed over the dips
  // (the solves of different dips overlap on threads).
  double seconds = 0, constants_seconds = 0, mesh_seconds = 0, dem_seconds = 0, fe_seconds = 0;
  double fe_joints_seconds = 0;  // the FE twins with the joints, summed over the dips
};

// Runs the measurements and the gate for a 3D scene (its joint_set.dip_deg is ignored: every beta is run). Throws
// SceneError for a scene that is not 3D or that has a second joint set (the five constants are of one set).
Elastic3Report run_elastic_gate3(const Scene& scene, const Elastic3Options& options = {});

// elastic.json of a 3D scene: the 2D names (docs/elastic.md) and dimension = 3.
nlohmann::json elastic3_json(const Elastic3Report& report, const Scene& scene);

// The readable table: one row per beta, the constants and the verdict.
std::string elastic3_table(const Elastic3Report& report);

}  // namespace rbdem::compare
