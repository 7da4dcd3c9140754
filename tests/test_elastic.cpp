// The elastic gate (compare/gate): the strain gauge and the compliance fit on exact data, the gate on the paper's
// scene and on a scene that is not an equivalent continuum, the elastic.json contract and the verdict cache.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>
#include <omp.h>

#include "compare/gate/dem_constants.hpp"
#include "compare/gate/elastic_gate.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/driver/ucs.hpp"
#include "dem/topology.hpp"
#include "io/results.hpp"

namespace rbdem {
namespace {

using compare::ElasticGateOptions;
using compare::ElasticReport;

// An affine displacement field on the specimen's blocks is measured exactly, whatever the end zones.
TEST(DemConstants, GaugeRecoversAnAffineFieldExactly) {
  Scene s;
  s.mesh.size = 0.004;
  const Topology topo = build_topology(make_mesh(s), s.specimen.thickness, s.rock.density);
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

TEST(Elastic, DefaultSceneAtCoarseMeshPassesTheGate) {
  Scene scene;
  scene.mesh.size = 0.0015;
  ElasticGateOptions o;
  o.fields = true;
  const ElasticReport r = compare::run_elastic_gate(scene, o);
  EXPECT_TRUE(r.gate.passed) << compare::elastic_table(r);
  EXPECT_LE(r.gate.max_deviation, scene.elastic.tolerance);
  EXPECT_TRUE(r.dem.admissible);
  ASSERT_EQ(r.angles.size(), 7u);
  for (const auto& a : r.angles) {
    // Frictionless platens: the FE twin with the DEM constants is Amadei's formula (a patch test).
    EXPECT_NEAR(a.fe / a.amadei, 1.0, 1e-6) << "beta " << a.beta_deg;
    EXPECT_GT(a.fe_goodman, 0.0);
    // The DEM displacements follow the continuum's within a few per cent.
    EXPECT_LT(a.field_l2, 0.10) << "beta " << a.beta_deg;
  }
  // Joints normal to the load soften the specimen: E(0) < E(90) for the DEM, Amadei and Goodman.
  EXPECT_LT(r.angles.front().dem_static, r.angles.back().dem_static);
  EXPECT_LT(r.angles.front().amadei, r.angles.back().amadei);
  EXPECT_LT(r.goodman.constants.E_prime, r.goodman.constants.E);
}

// Joints 40 mm apart in a 50 x 100 mm specimen, 80 times softer than the rock: two or three joints cut the
// specimen, which then is a stack of blocks and not an equivalent transversely isotropic continuum. Whatever the
// measured constants, some dip misses Amadei's curve by more than the tolerance, and the table says which.
TEST(Elastic, InconsistentSceneFailsWithReadableTable) {
  Scene scene;
  scene.mesh.size = 0.003;
  scene.joint_set.spacing = 0.04;
  scene.joint.effective_modulus = 2e9;
  const ElasticReport r = compare::run_elastic_gate(scene);
  EXPECT_FALSE(r.gate.passed);
  EXPECT_GT(r.gate.max_deviation, 2.0 * scene.elastic.tolerance);
  const std::string table = compare::elastic_table(r);
  EXPECT_NE(table.find("FAILED"), std::string::npos) << table;
  EXPECT_NE(table.find("<- worst"), std::string::npos) << table;
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
  ASSERT_TRUE(j["angles"].is_array());
  ASSERT_EQ(j["angles"].size(), 7u);
  for (const auto& a : j["angles"]) {
    for (const char* key : {"beta_deg", "amadei_pa", "dem_static_pa", "fe_pa", "fe_goodman_pa", "dem_gauge_pa"})
      EXPECT_TRUE(a[key].is_number()) << key;
    EXPECT_TRUE(a["field_l2"].is_number());
    EXPECT_EQ(a["fields"]["dem_ux"].size(), a["blocks"].get<std::size_t>());
    EXPECT_EQ(a["fields"]["fe_uy"].size(), a["blocks"].get<std::size_t>());
  }
  EXPECT_TRUE(j["gate"]["tolerance"].is_number());
  EXPECT_TRUE(j["gate"]["passed"].is_boolean());
  EXPECT_EQ(j["gate"]["measure"], "dem_gauge");
  EXPECT_EQ(j["scene"]["mesh"]["size"], 0.004);
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
  const Topology topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  const TestResult r = run_ucs(scene, topo);
  const int expected = std::getenv("OMP_NUM_THREADS") ? omp_get_max_threads() : cores;
  EXPECT_EQ(r.threads, expected);
  EXPECT_EQ(io::run_summary(scene, r)["threads"].get<int>(), expected);
}

}  // namespace
}  // namespace rbdem
