// The elastic gate (compare/gate): the strain gauge and the compliance fit on exact data, the gate on the paper's
// scene, on soft joints and on thin layers (where the layers do not homogenize and the FE model with the joints
// decides), a joint stiffer than the rock, a DEM whose joints slide, the elastic.json contract and the verdict cache.
#include <gtest/gtest.h>

#include <cstdio>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>
#include <omp.h>

#include "compare/gate/dem_constants.hpp"
#include "compare/gate/elastic_gate.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/driver/driver.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/version.hpp"
#include "io/results.hpp"

namespace rbdem {
namespace {

using compare::ElasticGateOptions;
using compare::ElasticReport;

// An affine displacement field on the specimen's blocks is measured exactly, whatever the end zones.
TEST(DemConstants, GaugeRecoversAnAffineFieldExactly) {
  Scene s;
  s.mesh.size = 0.004;
  const Topology<2> topo = build_topology(make_mesh(s), s.specimen.thickness, s.rock.density);
  std::vector<double> ux, uy;
  for (std::size_t b = 0; b < topo.blocks.size(); ++b) {
    const double x = topo.blocks.cx[b], y = topo.blocks.cy[b];
    ux.push_back(1e-7 + 2e-5 * x + 3e-6 * y);
    uy.push_back(-4e-7 + 1e-6 * x - 5e-5 * y);
  }
  const compare::GaugeStrain g = compare::gauge_strain(topo, ux, uy, 0.15);
  EXPECT_NEAR(g.eps_xx, 2e-5, 1e-15);
  EXPECT_NEAR(g.eps_yy, -5e-5, 1e-15);
  EXPECT_NEAR(g.gamma_xy, 4e-6, 1e-15);
  EXPECT_NEAR(g.rotation, -1e-6, 1e-15);
  EXPECT_LT(g.misfit, 1e-9);
  EXPECT_LT(g.blocks, topo.blocks.size());
}

// Virtual tests made from known constants give those constants back, with zero residual.
TEST(DemConstants, ComplianceFitRecoversKnownConstants) {
  // nu' = nu E'/E: the relation nu'/E' = nu/E that closes the plane-strain fit (and fixes nu in plane stress)
  const theory::TIConstants c{60e9, 0.2, 25e9, 0.2 * 25.0 / 60.0, 9e9};
  for (const auto plane : {theory::Plane::strain, theory::Plane::stress}) {
    const auto a = theory::reduced_compliance(c, plane);
    std::vector<compare::VirtualTest> tests;
    for (double beta : {0.0, 45.0, 90.0}) {
      const auto S = theory::rotated_compliance(a, beta);
      compare::VirtualTest t;
      t.beta_deg = beta, t.S12 = S[0][1], t.S22 = S[1][1], t.S26 = S[1][2];
      tests.push_back(t);
    }
    const compare::ComplianceFit f = compare::fit_compliance(tests, plane);
    EXPECT_LT(f.residual, 1e-12);
    EXPECT_TRUE(f.admissible);
    EXPECT_NEAR(f.constants.E / c.E, 1.0, 1e-9);
    EXPECT_NEAR(f.constants.E_prime / c.E_prime, 1.0, 1e-9);
    EXPECT_NEAR(f.constants.G_prime / c.G_prime, 1.0, 1e-9);
    EXPECT_NEAR(f.constants.nu_prime, c.nu_prime, 1e-9);
    EXPECT_NEAR(f.constants.nu, c.nu, 1e-9);
  }
}

// The seven-dip fit weighs each test by its own |S22|: with E/E' = 100 (joints far softer than the rock) it still
// recovers every constant, and the condition number stays small.
TEST(DemConstants, WeightedSevenDipFitStaysWellConditionedAtLargeContrast) {
  const theory::TIConstants c{280e9, 0.1, 2.8e9, 0.001, 1.2e9};
  const auto a = theory::reduced_compliance(c, theory::Plane::strain);
  std::vector<compare::VirtualTest> tests;
  for (double beta : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0}) {
    const auto S = theory::rotated_compliance(a, beta);
    compare::VirtualTest t;
    // 0.1 % relative noise of alternating sign on every measured entry
    const double e = (int(beta / 15) % 2 ? 1e-3 : -1e-3);
    t.beta_deg = beta, t.S12 = S[0][1] * (1 + e), t.S22 = S[1][1] * (1 - e), t.S26 = S[1][2] * (1 + e);
    tests.push_back(t);
  }
  const compare::ComplianceFit f = compare::fit_compliance(tests, theory::Plane::strain);
  EXPECT_EQ(f.tests, 7u);
  EXPECT_LT(f.condition, 20.0);
  EXPECT_LT(f.residual, 2e-3);
  EXPECT_NEAR(f.constants.E / c.E, 1.0, 0.01);  // the stiff direction, 100 times stiffer
  EXPECT_NEAR(f.constants.E_prime / c.E_prime, 1.0, 0.01);
  EXPECT_NEAR(f.constants.G_prime / c.G_prime, 1.0, 0.01);
}

// The paper scene: the FE model with the joints decides and the DEM follows it closely; homogenization applies, so
// Amadei's curve is reported as a fair comparison and the DEM follows it too.
TEST(Elastic, DefaultSceneAtCoarseMeshPassesTheGate) {
  Scene scene;
  scene.mesh.size = 0.0015;
  ElasticGateOptions o;
  o.fields = true;
  const ElasticReport r = compare::run_elastic_gate(scene, o);
  const std::string table = compare::elastic_table(r);
  EXPECT_TRUE(r.gate.passed) << table;
  EXPECT_EQ(r.gate.comparison, "fe_joints") << table;
  EXPECT_LE(r.gate.max_deviation, 0.01) << table;  // measured 0.1 % at 1.5 mm
  EXPECT_FALSE(r.linear_check_run);
  EXPECT_NE(r.gate.message.find("FE model with the joints"), std::string::npos) << r.gate.message;
  EXPECT_NE(r.gate.message.find("the comparison that always applies"), std::string::npos) << r.gate.message;
  EXPECT_TRUE(r.homogenization.applies) << table;
  EXPECT_TRUE(r.amadei.applicable) << table;
  EXPECT_NE(r.gate.message.find("homogenization applies"), std::string::npos) << r.gate.message;
  EXPECT_LE(r.amadei.max_deviation, scene.elastic.tolerance);
  EXPECT_TRUE(r.dem.admissible);
  EXPECT_EQ(r.interfaces.glued, 0u);
  EXPECT_GT(r.interfaces.edges, 0u);
  ASSERT_EQ(r.angles.size(), 7u);
  for (const auto& a : r.angles) {
    // Frictionless platens: the FE twin with the DEM constants is Amadei's formula (a patch test).
    EXPECT_NEAR(a.fe / a.amadei, 1.0, 1e-6) << "beta " << a.beta_deg;
    EXPECT_GT(a.fe_goodman, 0.0);
    EXPECT_EQ(a.interface_edges, a.test.joint_bonds);
    // The DEM displacements follow both continua within a few per cent.
    EXPECT_LT(a.field_l2, 0.10) << "beta " << a.beta_deg;
    EXPECT_LT(a.field_l2_joints, 0.10) << "beta " << a.beta_deg;
  }
  // Joints normal to the load soften the specimen: E(0) < E(90) for the DEM, Amadei and Goodman.
  EXPECT_LT(r.angles.front().dem_static, r.angles.back().dem_static);
  EXPECT_LT(r.angles.front().amadei, r.angles.back().amadei);
  EXPECT_LT(r.goodman.constants.E_prime, r.goodman.constants.E);
}

// Joints 3200 times softer than the rock (E*_j = 5e7 Pa), 5 layers across: the layers do not homogenize (Amadei
// misses the DEM by tens of per cent and says why) but the DEM follows the FE model with the joints. The DEM's
// linear parts open in tension where the layers bend, which the linear FE model cannot represent, so the linear
// check decides. 1.5 mm: 7 blocks across a layer (at 2 mm the DEM's layers are 7 % too soft in bending with 5
// blocks across, and the gate fails; docs/elastic.md).
TEST(Elastic, SoftJointsPassOnTheFeModelWithTheJoints) {
  Scene scene;
  scene.mesh.size = 0.0015;
  scene.joint.effective_modulus = 5e7;
  const ElasticReport r = compare::run_elastic_gate(scene);
  const std::string table = compare::elastic_table(r);
  EXPECT_TRUE(r.gate.passed) << table;
  EXPECT_EQ(r.gate.comparison, "fe_joints_linear") << table;
  EXPECT_TRUE(r.linear_check_run);
  EXPECT_FALSE(r.homogenization.applies);
  EXPECT_GT(r.homogenization.measured_error, 0.5) << table;  // the layers do not homogenize: measured
  EXPECT_FALSE(r.amadei.applicable);
  EXPECT_GT(r.amadei.max_deviation, 0.1) << table;
  EXPECT_GT(r.dem.residual, r.amadei.max_residual_for_ti) << table;  // the DEM is not one TI continuum
  EXPECT_NE(r.gate.message.find("Amadei not applicable"), std::string::npos) << r.gate.message;
  EXPECT_NE(r.gate.message.find("layers do not homogenize"), std::string::npos) << r.gate.message;
  EXPECT_NE(r.gate.message.find("linear parts open in tension"), std::string::npos) << r.gate.message;
  std::size_t fe_open = 0, dem_open = 0;
  for (const auto& a : r.angles) {
    EXPECT_LT(std::abs(a.dem_linear / a.fe_joints_linear - 1), scene.elastic.tolerance) << "beta " << a.beta_deg;
    EXPECT_LE(a.dem_gauge, a.dem_linear * (1 + 1e-9)) << "beta " << a.beta_deg;  // opening only softens
    // The FE model's unilateral joints open where the DEM's joint bonds do, and only soften it.
    EXPECT_TRUE(a.fe_joints_states_settled) << "beta " << a.beta_deg;
    EXPECT_LE(a.fe_joints, a.fe_joints_linear * (1 + 1e-9)) << "beta " << a.beta_deg;
    if (a.beta_deg >= 30 && a.beta_deg <= 75) fe_open += a.fe_joints_open_edges, dem_open += a.test.open_joint_bonds;
  }
  EXPECT_GT(dem_open, 0u) << table;
  EXPECT_NEAR(double(fe_open) / double(dem_open), 1.0, 0.25) << table;  // 1 mm: 358 against 320
  // Where the joints carry no load (dips 0 and 90: uniform stress) both models agree closely.
  EXPECT_LT(std::abs(r.angles.front().deviation_joints(compare::GateMeasure::gauge)), 0.01) << table;
  EXPECT_LT(std::abs(r.angles.back().deviation_joints(compare::GateMeasure::gauge)), 0.01) << table;
}

// Thin layers (spacing 4 mm at 2 mm, two blocks across a layer, like the 2 mm spacing at the 1 mm default mesh):
// the DEM's rock lattice in two-block layers is not the unjointed specimen's (its modulus zig-zags with the dip),
// the seven-dip fit shows the DEM is not one TI continuum, and the FE model with the joints, whose layers are the
// rock measured on the same mesh, decides and agrees.
TEST(Elastic, ThinLayersPassOnTheFeModelWithTheJoints) {
  Scene scene;
  scene.mesh.size = 0.002;
  scene.joint_set.spacing = 0.004;
  const ElasticReport r = compare::run_elastic_gate(scene);
  const std::string table = compare::elastic_table(r);
  EXPECT_TRUE(r.gate.passed) << table;
  EXPECT_EQ(r.gate.comparison, "fe_joints") << table;
  EXPECT_LT(r.gate.max_deviation, 0.01) << table;  // measured 0.15 %
  double lo = 1e300, hi = 0;
  for (const auto& a : r.angles) lo = std::min(lo, a.rock_test.gauge_modulus), hi = std::max(hi, a.rock_test.gauge_modulus);
  EXPECT_GT(hi / lo - 1, 0.05) << table;  // the rock of two-block layers depends on the dip
  EXPECT_NE(r.gate.message.find("passed: DEM within"), std::string::npos) << r.gate.message;
}

// Beds of two rocks alternating every joint spacing (beds.pattern), rock2 with half the rock's effective modulus:
// the FE model with the joints gives each layer its own rock's constants, measured on the same mesh, and decides.
// The DEM is linear in E* at a fixed kappa, so rock2 of the layers is half as stiff with the same Poisson's ratio.
// Beside it, Salamon's interbedded medium with the joints (the interbedded column) and the FE model with the joints
// on the intact rocks against it (homog).
TEST(Elastic, InterbeddedBedsPassWithBothRocksInTheFeModel) {
  Scene scene;
  scene.mesh.size = 0.002;
  scene.beds.pattern = "rock, rock2";
  scene.rock2.effective_modulus = 0.5 * scene.rock.effective_modulus;
  const ElasticReport r = compare::run_elastic_gate(scene);
  const std::string table = compare::elastic_table(r);
  std::printf("%s", table.c_str());
  EXPECT_TRUE(r.two_rocks);
  EXPECT_TRUE(r.gate.passed) << table;
  EXPECT_EQ(r.gate.comparison, "fe_joints") << table;
  EXPECT_NEAR(r.intact2_constants.E / r.intact_constants.E, 0.5, 1e-9) << table;
  EXPECT_NEAR(r.intact2_constants.nu, r.intact_constants.nu, 1e-9) << table;
  ASSERT_EQ(r.angles.size(), 7u);
  for (const auto& a : r.angles) {
    EXPECT_NEAR(a.rock2_constants.E / a.rock_constants.E, 0.5, 1e-9) << "beta " << a.beta_deg;
    EXPECT_NEAR(a.rock2_constants.nu, a.rock_constants.nu, 1e-9) << "beta " << a.beta_deg;
    EXPECT_TRUE(std::isfinite(a.interbedded)) << "beta " << a.beta_deg;
    EXPECT_LT(std::abs(a.deviation_joints(compare::GateMeasure::gauge)), scene.elastic.tolerance) << table;
    // Salamon's medium of the same rocks and joints describes the DEM and the FE model with the joints within the
    // gate's tolerance too (measured: 1.5 % and 0.7 % at worst, 60 deg), and the FE model on the intact rocks.
    EXPECT_LT(std::abs(a.dem_gauge / a.interbedded - 1.0), scene.elastic.tolerance) << table;
    EXPECT_LT(std::abs(a.fe_joints / a.interbedded - 1.0), scene.elastic.tolerance) << table;
    EXPECT_LT(std::abs(a.homogenization_error()), scene.elastic.tolerance) << table;
  }
  // Softer rock2 softens the specimen: the DEM lies below Amadei's modulus of the rock's own layers with the
  // same joints at every dip (Goodman's medium on the rock of the layers, the FE Goodman column's rock).
  for (const auto& a : r.angles) EXPECT_LT(a.dem_gauge, a.fe_goodman) << "beta " << a.beta_deg;
}

// A joint stiffer than the rock (E*_j > E*_r, same kappa) has no extra compliance to give an interface: every joint
// edge is glued, the report says so, and the FE model with the joints is the rock of the layers alone.
TEST(Elastic, JointStifferThanTheRockIsGluedAndReported) {
  Scene scene;
  scene.mesh.size = 0.003;
  scene.joint.effective_modulus = 2.4e11;  // rock 1.6e11
  const ElasticReport r = compare::run_elastic_gate(scene);
  const std::string table = compare::elastic_table(r);
  EXPECT_GT(r.interfaces.edges, 0u);
  EXPECT_EQ(r.interfaces.glued, r.interfaces.edges);
  EXPECT_FALSE(r.interfaces.note.empty());
  EXPECT_NE(table.find("glued"), std::string::npos) << table;
  EXPECT_EQ(r.homogenization.compliance_ratio, 0.0);
  for (const auto& a : r.angles) {
    EXPECT_EQ(a.glued_edges, a.interface_edges);
    // glued: the rock of the layers alone, whose constants reproduce the rock test's gauge modulus
    EXPECT_NEAR(a.fe_joints / a.rock_test.gauge_modulus, 1.0, 0.005) << "beta " << a.beta_deg;
  }
  const nlohmann::json j = compare::elastic_json(r, scene);
  EXPECT_EQ(j["joint_interfaces"]["glued_edges"], r.interfaces.edges);
  EXPECT_TRUE(j["joint_interfaces"]["k_n_mean"].is_null());  // +inf
}

// Joints whose linear parts slide while bonded (joint.slip_when_bonded, no friction) are softer in shear than the
// sticking interfaces of the FE model: the gate fails, the message names the comparison, and the linear check does
// not excuse sliding but says so and names the fix.
TEST(Elastic, SlidingJointsFailWithAMessageNamingTheComparisonAndTheFix) {
  Scene scene;
  scene.mesh.size = 0.003;
  scene.joint.effective_modulus = 5e9;
  scene.joint.contact_friction = 0.0;
  scene.joint.slip_when_bonded = true;
  const ElasticReport r = compare::run_elastic_gate(scene);
  const std::string table = compare::elastic_table(r);
  EXPECT_FALSE(r.gate.passed) << table;
  EXPECT_EQ(r.gate.comparison, "fe_joints");
  EXPECT_GT(r.gate.max_deviation, scene.elastic.tolerance);
  EXPECT_TRUE(r.linear_check_run);
  EXPECT_TRUE(r.linear_check_sliding) << table;
  EXPECT_NE(table.find("FAILED"), std::string::npos) << table;
  EXPECT_NE(table.find("<- worst"), std::string::npos) << table;
  EXPECT_NE(r.gate.reason.find("fe_joints"), std::string::npos) << r.gate.reason;
  EXPECT_NE(r.gate.reason.find("contact_friction"), std::string::npos) << r.gate.reason;
  EXPECT_NE(r.gate.reason.find(fmt::format("beta = {:g} deg", r.gate.worst_beta_deg)), std::string::npos)
      << r.gate.reason;
  // the worst row is the one marked
  const auto marked = table.rfind('\n', table.find("<- worst"));
  EXPECT_EQ(std::stod(table.substr(marked + 1, 5)), r.gate.worst_beta_deg) << table;
}

TEST(Elastic, JsonHasTheContractKeys) {
  Scene scene;
  scene.mesh.size = 0.004;
  ElasticGateOptions o;
  o.fields = true;
  const nlohmann::json j = compare::elastic_json(compare::run_elastic_gate(scene, o), scene);
  for (const char* set : {"dem", "goodman"})
    for (const char* key : {"E", "nu", "E_prime", "nu_prime", "G_prime"})
      EXPECT_TRUE(j["constants"][set][key].is_number()) << set << "." << key;
  for (const char* key : {"fit_residual", "fit_condition"}) EXPECT_TRUE(j["constants"]["dem"][key].is_number()) << key;
  for (const char* key : {"k_n_mean", "k_s_mean", "interface_edges", "glued_edges"})
    EXPECT_TRUE(j["joint_interfaces"][key].is_number()) << key;
  for (const char* key : {"layers_across", "contrast", "compliance_ratio", "indicator", "measured_error"})
    EXPECT_TRUE(j["homogenization"][key].is_number()) << key;
  EXPECT_TRUE(j["homogenization"]["applies"].is_boolean());
  EXPECT_TRUE(j["amadei"]["applicable"].is_boolean());
  ASSERT_TRUE(j["angles"].is_array());
  ASSERT_EQ(j["angles"].size(), 7u);
  for (const auto& a : j["angles"]) {
    for (const char* key : {"beta_deg", "amadei_pa", "dem_static_pa", "fe_pa", "fe_goodman_pa", "dem_gauge_pa",
                            "fe_joints_pa", "fe_joints_platen_pa", "dem_gauge_vs_fe_joints",
                            "dem_static_vs_fe_joints_platen", "interface_edges", "glued_edges"})
      EXPECT_TRUE(a[key].is_number()) << key;
    EXPECT_TRUE(a["field_l2"].is_number());
    EXPECT_TRUE(a["field_l2_joints"].is_number());
    for (const char* key : {"dem_ux", "fe_uy", "fe_joints_ux", "fe_joints_uy"})
      EXPECT_EQ(a["fields"][key].size(), a["blocks"].get<std::size_t>()) << key;
  }
  EXPECT_TRUE(j["gate"]["tolerance"].is_number());
  EXPECT_TRUE(j["gate"]["passed"].is_boolean());
  EXPECT_EQ(j["gate"]["measure"], "dem_gauge");
  EXPECT_EQ(j["gate"]["comparison"], "fe_joints");
  EXPECT_TRUE(j["gate"]["message"].is_string());
  EXPECT_TRUE(j["timing"]["fe_joints_seconds"].is_number());
  EXPECT_EQ(j["scene"]["mesh"]["size"], 0.004);
  EXPECT_EQ(j["version"], version_text());
}

// The cache key covers what changes the elastic response and nothing else; a verdict is computed once.
TEST(Elastic, GateVerdictIsCachedUnderAKeyOfTheElasticScene) {
  Scene a;
  a.mesh.size = 0.004;
  Scene b = a;
  b.joint_set.dip_deg = 30, b.rock.cohesion = 1e6, b.joint.tensile_strength = 1e6, b.loading.platen_velocity = 0.1;
  b.loading.platen_friction = 0.3, b.numerics.threads = 1;
  EXPECT_EQ(compare::elastic_gate_key(a), compare::elastic_gate_key(b));
  for (const char* change : {"joint.effective_modulus=40e9", "rock.contact_friction=0.31", "mesh.size=0.005",
                             "joint_set.spacing=0.02", "elastic.tolerance=0.1", "specimen.model=plane_stress"}) {
    Scene c = a;
    apply_override(c, change);
    EXPECT_NE(compare::elastic_gate_key(a), compare::elastic_gate_key(c)) << change;
  }
  // another build of rbdem never reuses a verdict
  EXPECT_NE(compare::elastic_gate_key_text(a).find("rbdem=" + version_text() + "\n"), std::string::npos);
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem-gate-cache-test-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  ::setenv("RBDEM_CACHE_DIR", dir.c_str(), 1);
  const compare::GateCheck first = compare::check_elastic_gate(a);
  const compare::GateCheck second = compare::check_elastic_gate(b);
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(first.status, second.status);
  EXPECT_EQ(first.table, second.table);
  EXPECT_TRUE(std::filesystem::exists(first.cache_file));
  // a cache folder that cannot be created is not an error
  ::setenv("RBDEM_CACHE_DIR", "/proc/rbdem-cannot-write-here", 1);
  EXPECT_NO_THROW(compare::check_elastic_gate(a));
  ::unsetenv("RBDEM_CACHE_DIR");
  std::filesystem::remove_all(dir);
}

// numerics.threads = 0 means all cores: the engine of a run must get them after everything that runs before it in
// the same process (meshing with gmsh, the elastic gate with its deal.II solves, the static elastic start), and
// the summary must say how many it used. gmsh's initialisation used to leave OpenMP's default at one thread.
TEST(Threads, DefaultThreadsUseEveryCoreAfterMeshingTheGateAndTheStaticStart) {
  const int cores = omp_get_num_procs();
  if (cores < 2) GTEST_SKIP() << "needs a machine with more than one core";
  Scene scene;
  scene.mesh.size = 0.004;
  scene.numerics.threads = 0;
  ASSERT_TRUE(scene.numerics.elastic_start);
  compare::ElasticGateOptions go;
  go.with_fe = true;
  (void)compare::run_elastic_gate(scene, go);
  const TestResult r = run_test("ucs", scene, make_mesh(scene));
  const int expected = std::getenv("OMP_NUM_THREADS") ? omp_get_max_threads() : cores;
  EXPECT_EQ(r.threads, expected);
  EXPECT_EQ(io::run_summary(scene, r)["threads"].get<int>(), expected);
}

}  // namespace
}  // namespace rbdem

