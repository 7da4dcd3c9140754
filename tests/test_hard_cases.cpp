// Hard cases that must run and stay stable (docs/reliability.md, "Checkpoints, watchdog and hard cases"): sliver
// triangles, a rock/joint stiffness contrast of 1e4, 1 mm layers, neighbouring blocks of 0.1 and 5 mm, a platen so
// fast the test is not quasi-static (and the summary says so), and a granular pile with every bond broken.
// Each asserts that the watchdog let the run complete with finite numbers, and where a hard case has a number to
// meet (the soft joints' modulus, the pile's weakness) that number.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/driver/driver.hpp"
#include "io/results.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

// A structured mesh on the grid xs x ys, each cell cut into two counter-clockwise triangles along alternating
// diagonals; row r of cells belongs to layer layer_of_row[r].
TriMesh grid_mesh(const std::vector<double>& xs, const std::vector<double>& ys, const std::vector<int>& layer_of_row) {
  TriMesh m;
  const int nx = int(xs.size()), ny = int(ys.size());
  for (double y : ys)
    for (double x : xs) m.nodes.push_back({x, y});
  auto id = [&](int i, int j) { return j * nx + i; };
  int layers = 0;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) m.triangles.push_back({a, b, c}), m.triangles.push_back({a, c, d});
      else m.triangles.push_back({a, b, d}), m.triangles.push_back({b, c, d});
      const int l = layer_of_row[std::size_t(j)];
      m.layer.push_back(l), m.layer.push_back(l);
      layers = std::max(layers, l + 1);
    }
  for (int l = 0; l < layers; ++l) m.layer_names.push_back("layer_" + std::to_string(l));
  return m;
}

std::vector<double> steps(double from, double to, int n) {
  std::vector<double> v;
  for (int k = 0; k <= n; ++k) v.push_back(from + (to - from) * double(k) / double(n));
  return v;
}

Scene small_scene() {
  Scene s;
  s.specimen.width = 0.01, s.specimen.height = 0.02;
  s.joint_set.spacing = 0.006, s.joint_set.dip_deg = 30;
  s.mesh.size = 0.002;
  s.numerics.threads = 1;
  return s;
}

// The run completed (the watchdog did not stop it) and every number in its summary and curve is finite.
void expect_sound(const TestResult& r, const Scene& scene) {
  EXPECT_TRUE(r.completed) << r.watchdog_message;
  EXPECT_TRUE(std::isfinite(r.peak_stress) && std::isfinite(r.youngs_modulus));
  for (const auto& p : r.curve)
    ASSERT_TRUE(std::isfinite(p.stress_top) && std::isfinite(p.stress_bottom) && std::isfinite(p.kinetic) &&
                std::isfinite(p.strain_energy))
        << "step " << p.step;
  EXPECT_LT(r.energy_ratio_max, 1.5);
  nlohmann::json j = io::run_summary(scene, r);
  EXPECT_TRUE(j["watchdog"].is_null());
  j.erase("watchdog");
  // The signals are null where the curve does not define them (docs/outputs.md), e.g. no residual strength after a
  // run stopped by the stress drop; every other number must be finite.
  for (const char* key : {"poisson_ratio_at_half_peak", "crack_initiation_stress_pa", "crack_damage_stress_pa",
                          "residual_stress_pa", "crack_initiation_to_peak", "crack_damage_to_peak", "residual_to_peak"})
    j.erase(key);
  const std::string s = j.dump();  // NaN and infinity would print as null
  EXPECT_EQ(s.find("null"), std::string::npos) << "a completed run's summary has no null values";
}

TEST(HardCases, SliverTrianglesOfAspectRatio30) {
  Scene scene = small_scene();
  // 0.3 mm x 9 mm cells: triangles with an edge 30 times the shortest altitude.
  const TriMesh mesh = grid_mesh(steps(0.0, 0.0102, 34), {0.0, 0.009, 0.018}, {0, 1});
  const TestResult r = run_test("ucs", scene, mesh);
  expect_sound(r, scene);
  EXPECT_GT(r.peak_stress, 1e6);
}

// Two joint sets 5 deg apart: where their joints cross at that shallow angle gmsh leaves wedges a tenth of an element
// thick (slivers); the run stays sound on the smaller step they set. And joints with rock bridges whose pieces end
// inside the layers.
TEST(HardCases, TwoSetsFiveDegreesApartAndRockBridges) {
  Scene scene = small_scene();
  scene.mesh.size = 0.001;
  scene.joint_set2.enabled = true, scene.joint_set2.follows_set1 = true, scene.joint_set2.dip_deg = 5.0;
  scene.joint_set2.spacing = 0.005;
  const TriMesh crossed = make_mesh(scene);
  const Topology<2> topo = build_topology(crossed, scene.specimen.thickness, scene.rock.density);
  double shortest = 1e300;
  for (double l : topo.bonds.length) shortest = std::min(shortest, l);
  EXPECT_LT(shortest, 0.25 * scene.mesh.size);  // the slivers are there
  const TestResult r = run_test("ucs", scene, crossed);
  expect_sound(r, scene);
  EXPECT_GT(r.peak_stress, 1e6);

  Scene bridges = small_scene();
  bridges.mesh.size = 0.001;
  bridges.joint_set.persistence = 0.5, bridges.joint_set.joint_length = 0.004;
  const TriMesh pieces = make_mesh(bridges);
  const TestResult b = run_test("ucs", bridges, pieces);
  expect_sound(b, bridges);
  EXPECT_GT(b.peak_stress, 1e6);
}

// Joints 1e4 times softer than the rock: the step is set by the stiff rock while the soft joints take the strain,
// so the explicit run integrates many steps per unit of deformation. From the static start (numerics.elastic_start)
// the run must load quasi-statically, and the stress of its explicit samples before the first crack must follow the
// static solve's apparent modulus of the same mesh. (Started from rest instead, the platen's first contact is an
// impact on the stiff top blocks: the platen forces differ by 200 % and the "peak" is the impact's.)
TEST(HardCases, RockJointStiffnessContrast1e4) {
  Scene scene = small_scene();
  scene.joint.effective_modulus = scene.rock.effective_modulus * 1e-4;
  // The soft joints take a large strain to fail: faster than the default 0.01 m/s for fewer steps, but not as fast
  // as 0.1 m/s, where the platen forces differ by 15 % while loading (not quasi-static).
  scene.loading.platen_velocity = 0.02;
  const TriMesh mesh = make_mesh(scene);
  const TestResult r = run_test("ucs", scene, mesh);
  expect_sound(r, scene);
  EXPECT_TRUE(r.quasi_static) << r.quasi_static_reason;
  const double modulus = fixtures::with_platens(scene)->solve_static().apparent_modulus;
  int explicit_samples = 0;
  for (const CurvePoint& p : r.curve) {
    if (p.step <= 0 || p.broken[0] + p.broken[1] + p.broken[2] + p.broken[3] > 0) continue;
    ++explicit_samples;
    EXPECT_NEAR(p.stress() / (modulus * p.strain), 1.0, 0.05) << "step " << p.step;
  }
  EXPECT_GT(explicit_samples, 0);
}

TEST(HardCases, OneMillimetreLayers) {
  Scene scene = small_scene();
  scene.joint_set.spacing = 0.001, scene.mesh.size = 0.0005;  // two elements per layer
  scene.specimen.width = 0.004, scene.specimen.height = 0.008;
  const TriMesh mesh = make_mesh(scene);
  const TestResult r = run_test("ucs", scene, mesh);
  expect_sound(r, scene);
  EXPECT_GT(r.joint_bonds, 50u);
}

TEST(HardCases, NeighbouringBlocksOfTenthAndFiveMillimetres) {
  Scene scene = small_scene();
  // 5 mm cells next to 0.1 mm strips and 0.1 x 0.1 mm cells at the crossings.
  const TriMesh mesh = grid_mesh({0.0, 0.005, 0.0051, 0.0101}, {0.0, 0.005, 0.0051, 0.0101, 0.0151, 0.0152, 0.0202},
                                 {0, 0, 0, 1, 1, 1});
  scene.loading.platen_velocity = 0.05;  // the 0.1 mm blocks set a 50 times smaller step: fewer steps
  const TestResult r = run_test("ucs", scene, mesh);
  expect_sound(r, scene);
  EXPECT_GT(r.peak_stress, 1e6);
}

TEST(HardCases, FastPlatenIsReportedAsNotQuasiStatic) {
  Scene scene = small_scene();
  const TriMesh mesh = make_mesh(scene);
  const TestResult slow = run_test("ucs", scene, mesh);
  EXPECT_TRUE(slow.quasi_static) << slow.quasi_static_reason;
  scene.loading.platen_velocity = 20.0;  // m/s: 2000 times the quasi-static default
  const TestResult fast = run_test("ucs", scene, mesh);
  EXPECT_TRUE(fast.completed) << fast.watchdog_message;
  EXPECT_FALSE(fast.quasi_static);
  EXPECT_NE(fast.quasi_static_reason.find("platen_velocity"), std::string::npos) << fast.quasi_static_reason;
  const nlohmann::json j = io::run_summary(scene, fast);
  EXPECT_EQ(j["quasi_static"], false);
  EXPECT_TRUE(j.contains("platen_force_mismatch"));
}

TEST(HardCases, GranularPileWithEveryBondBroken) {
  Scene scene = small_scene();
  // Bonds with (next to) no strength: all break on the first step under load and the platens squeeze a pile of
  // loose blocks, held only by contacts.
  scene.rock.tensile_strength = scene.rock.cohesion = scene.joint.tensile_strength = scene.joint.cohesion = 1e-6;
  scene.rock.friction_deg = scene.joint.friction_deg = 0.0;  // compression does not strengthen them either
  // Brittle: a softening bond must still dissipate its fracture energy, over an opening of 2 G_f / sigma_c.
  scene.rock.fracture_energy = scene.joint.fracture_energy = 0.0;
  scene.loading.max_strain = 0.01;
  const TriMesh mesh = make_mesh(scene);
  const TestResult r = run_test("ucs", scene, mesh);
  EXPECT_TRUE(r.completed) << r.watchdog_message;
  for (const auto& p : r.curve) ASSERT_TRUE(std::isfinite(p.stress_top) && std::isfinite(p.kinetic));
  EXPECT_EQ(std::size_t(r.crack_counts.total()), r.bonds) << "every bond broke";
  EXPECT_LT(r.energy_ratio_max, 1.5);
  // Without cohesion the pile is weaker than the bonded specimen it was: the broken bonds carry nothing but their
  // contacts' compression and friction.
  Scene bonded = small_scene();
  bonded.loading.max_strain = 0.01;
  const TestResult intact = run_test("ucs", bonded, mesh);
  EXPECT_LT(r.peak_stress, 0.5 * intact.peak_stress) << "pile " << r.peak_stress << " Pa, bonded " << intact.peak_stress;
  EXPECT_GT(r.peak_stress, 0.0);
}

}  // namespace
}  // namespace rbdem
