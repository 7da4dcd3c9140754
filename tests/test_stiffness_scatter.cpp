// Stiffness heterogeneity (rock.stiffness_weibull_modulus and the other materials'): each bond's E* times a Weibull
// factor of mean 1 (dem/model.cpp, apply_stiffness_heterogeneity).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dem/driver/driver.hpp"
#include "dem/driver/registry.hpp"
#include "dem/model.hpp"
#include "dem/scene.hpp"
#include "dem/scene_keys.hpp"
#include "dem/simulation_impl.hpp"
#include "dem/topology.hpp"
#include "tests/simulations.hpp"
#include "tests/weibull_check.hpp"

namespace rbdem {
namespace {

// Every rock bond's K, K / kappa, rotational stiffness and softening r_u are the uniform model's times one factor
// s, which follows F(s) = 1 - exp(-(s Gamma(1 + 1/m))^m) (a Kolmogorov-Smirnov test at the 1 % level, the mean and
// coefficient of variation of the closed forms); joint bonds keep E*; the strengths are those of the scene without
// the stiffness scatter (their own stream), and the same seed gives the same factors.
TEST(Materials, WeibullStiffnessFactorsScaleTheBondsAndLeaveTheStrengths) {
  Scene plain;
  plain.mesh.size = 0.002;
  plain.rock.weibull_modulus = 3.0;
  plain.rock.fracture_energy = 1.0;
  Scene scene = plain;
  const double m = 2.5;
  scene.rock.stiffness_weibull_modulus = m;
  const Topology<2> topo = build_topology(make_mesh(scene), 1.0, scene.rock.density);
  const Model uniform = build_model(topo, plain, 1.0);
  const Model model = build_model(topo, scene, 1.0);
  EXPECT_EQ(model.frame.strength_factor, uniform.frame.strength_factor);
  EXPECT_EQ(model.frame.tension_limit, uniform.frame.tension_limit);
  EXPECT_EQ(model.frame.cohesion_A, uniform.frame.cohesion_A);
  std::vector<double> s;
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    const double f = model.frame.stiffness_factor[b];
    if (topo.bonds.kind[b] == BondKind::joint) {
      EXPECT_EQ(f, 1.0);
      EXPECT_EQ(model.frame.K[b], uniform.frame.K[b]);
      continue;
    }
    EXPECT_EQ(model.frame.K[b], f * uniform.frame.K[b]);
    EXPECT_EQ(model.frame.Ks[b], f * uniform.frame.Ks[b]);
    EXPECT_EQ(model.frame.KI[b], f * uniform.frame.KI[b]);
    EXPECT_NEAR(model.frame.rupture[b], f * uniform.frame.rupture[b], 1e-12 * model.frame.rupture[b]);
    const BondStiffness k = model.stiffness(int(b)), k0 = uniform.stiffness(int(b));  // what the static solve reads
    for (const auto& [got, base] : {std::pair{k.kbnA, k0.kbnA}, std::pair{k.kbsA, k0.kbsA},
                                    std::pair{k.kbnI, k0.kbnI}, std::pair{k.knA, k0.knA}, std::pair{k.ksA, k0.ksA}})
      EXPECT_DOUBLE_EQ(got, f * base);
    s.push_back(f);
  }
  expect_weibull_factors(s, m);
  EXPECT_EQ(build_model(topo, scene, 1.0).frame.stiffness_factor, model.frame.stiffness_factor);
  scene.mesh.strength_seed = 1;
  EXPECT_NE(build_model(topo, scene, 1.0).frame.stiffness_factor, model.frame.stiffness_factor);
}

// The energy of a static solution's bonds: parallel bond (normal, shear, moment) and linear part (normal, shear),
// each force squared over twice its stiffness.
std::vector<double> bond_energies(const StaticResult& r, const Model<2>& model) {
  std::vector<double> U(model.num_bonds());
  for (std::size_t b = 0; b < U.size(); ++b) {
    const double K = model.frame.K[b], Ks = model.frame.Ks[b], KI = model.frame.KI[b];
    U[b] = 0.5 * (r.fn_b[b] * r.fn_b[b] / K + r.fs_b[b] * r.fs_b[b] / Ks + r.m_b[b] * r.m_b[b] / KI +
                  r.fn_lin[b] * r.fn_lin[b] / K + r.fs_lin[b] * r.fs_lin[b] / Ks);
  }
  return U;
}

// The scattered network's static modulus between the two energy bounds of its realization. With the platen closure
// delta fixed, the work W = F delta / 2 is the stored energy. The uniform network's displacements are admissible for
// the scattered one: W_s <= sum_b s_b U_b + U_p (minimum potential energy; U_b the uniform solution's bond
// energies, U_p = W - sum U_b what the platen contacts hold). Its forces are statically admissible (the same
// equilibrium, compression in the linear parts): W_s >= W^2 / (sum_b U_b / s_b + U_p) (complementary energy). Each
// bound is exact for a uniform factor; the modulus lies between them whatever the factors.
TEST(Materials, StiffnessScatterModulusLiesBetweenTheEnergyBounds) {
  Scene plain;
  plain.mesh.size = 0.003;
  plain.numerics.threads = 1;
  for (const double dip : {90.0, 30.0}) {
    plain.joint_set.dip_deg = dip;
    Scene scene = plain;
    scene.rock.stiffness_weibull_modulus = 2.0;
    const Topology<2> topo = build_topology(make_mesh(plain), 1.0, plain.rock.density);
    const Model uniform = build_model(topo, plain, 1.0), model = build_model(topo, scene, 1.0);
    const StaticResult a = fixtures::with_platens(plain, topo)->solve_static();
    const StaticResult b = fixtures::with_platens(scene, topo)->solve_static();
    ASSERT_EQ(a.platen_displacement, b.platen_displacement);
    const double W = 0.5 * a.top_force * a.platen_displacement, Ws = 0.5 * b.top_force * b.platen_displacement;
    const std::vector<double> U = bond_energies(a, uniform);
    double sum = 0, voigt = 0, reuss = 0;
    for (std::size_t k = 0; k < U.size(); ++k) {
      const double s = model.frame.stiffness_factor[k];
      sum += U[k], voigt += s * U[k], reuss += U[k] / s;
    }
    const double Up = W - sum;
    ASSERT_GE(Up, -1e-9 * W);
    const double upper = (voigt + Up) / W, lower = W / (reuss + Up), ratio = Ws / W;
    EXPECT_LT(ratio, upper * (1 + 1e-6));
    EXPECT_GT(ratio, lower * (1 - 1e-6));
    EXPECT_LT(ratio, 0.99);  // softer than the uniform network: the bounds are apart
    std::printf("dip %g: E scattered / uniform %.4f, bounds [%.4f, %.4f], platens hold %.2f %% of the energy\n", dip,
                ratio, lower, upper, 100 * Up / W);
  }
}

// Stiff and soft bonds side by side break below the peak: at 90 deg on the 4 mm mesh the first crack comes at a
// lower fraction of the peak with the scatter than without, and more bonds break before the peak.
TEST(Materials, StiffnessScatterStartsCrackingBelowThePeak) {
  Scene plain;
  plain.mesh.size = 0.004;
  plain.joint_set.dip_deg = 90;
  plain.numerics.threads = 1;
  Scene scene = plain;
  scene.rock.stiffness_weibull_modulus = 2.0;
  const TriMesh mesh = make_mesh(plain);
  const TestResult a = run_test("ucs", plain, mesh), b = run_test("ucs", scene, mesh);
  ASSERT_TRUE(a.completed && b.completed);
  auto first_crack_to_peak = [](const TestResult& r) {  // the loading level (highest stress so far) at the first crack
    double first_strain = r.strain_at_peak, level = 0;
    for (const auto& c : r.cracks) first_strain = std::min(first_strain, c.strain);
    for (const auto& p : r.curve)
      if (p.strain <= first_strain) level = std::max(level, p.stress());
    return level / r.peak_stress;
  };
  EXPECT_LT(first_crack_to_peak(b), first_crack_to_peak(a) - 0.1);
  std::printf("first crack / peak: %.3f uniform, %.3f scattered; peaks %.2f, %.2f MPa\n", first_crack_to_peak(a),
              first_crack_to_peak(b), a.peak_stress / 1e6, b.peak_stress / 1e6);
}

// A 3D scene refuses the key: its face bonds keep every bond at E*.
TEST(Materials, StiffnessScatterIsRefusedIn3D) {
  Scene s;
  s.specimen.dimension = 3;
  s.specimen.shape = "cylinder";
  s.rock.stiffness_weibull_modulus = 3.0;
  try {
    validate(s);
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("rock.stiffness_weibull_modulus"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rbdem
