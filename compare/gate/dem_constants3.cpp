// The 3D DEM's constants from virtual tests on prisms. See dem_constants3.hpp.
#include "compare/gate/dem_constants3.hpp"

#include <chrono>
#include <thread>
#include <utility>

#include "common/parallel_map.hpp"

namespace rbdem::compare {

namespace {
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

VirtualTest3 virtual_test3(const Static3Result& r, double dip_deg, double seconds) {
  VirtualTest3 v;
  v.dip_deg = dip_deg;
  v.modulus = r.fit_modulus, v.platen_modulus = r.platen_modulus;
  v.poisson_strike = r.poisson_strike, v.poisson_dip = r.poisson_dip;
  v.joint_d_mean = r.joint_d_mean;
  v.blocks = r.blocks, v.joint_bonds = r.joint_bonds, v.dofs = r.dofs;
  v.seconds = seconds;
  return v;
}

Static3Options static3_options(const Scene& scene) {
  Static3Options o;
  o.rock = {scene.rock.effective_modulus, scene.rock.stiffness_ratio};
  o.joint = {scene.joint.effective_modulus, scene.joint.stiffness_ratio};
  o.dip_direction_deg = 0.0;
  return o;
}

theory::TIConstants isotropic_constants3(const VirtualTest3& t) {
  return theory::TIConstants::isotropic(t.modulus, 0.5 * (t.poisson_strike + t.poisson_dip));
}

theory::TIConstants ti_constants3(const VirtualTest3& at0, const VirtualTest3& at45, const VirtualTest3& at90) {
  theory::TIConstants c;
  // At 0 deg both lateral axes lie in the joint plane: each ratio is nu'.
  c.E_prime = at0.modulus, c.nu_prime = 0.5 * (at0.poisson_strike + at0.poisson_dip);
  // At 90 deg the strike is the other in-plane axis (nu); the dip direction is the normal (nu' E / E').
  c.E = at90.modulus, c.nu = at90.poisson_strike;
  c.G_prime = 1.0 / (4.0 / at45.modulus - 1.0 / c.E - 1.0 / c.E_prime + 2.0 * c.nu_prime / c.E_prime);
  return c;
}

SpecimenGeometry3 constants_prism(const Scene& scene) {
  SpecimenGeometry3 g = specimen_geometry3(scene);
  if (g.shape == Shape3::cylinder) g.width = g.depth = g.diameter;
  g.shape = Shape3::prism;
  g.set1.dip_direction_deg = 0.0;
  g.second_set = false;
  return g;
}

DemConstants3 measure_dem_constants3(const Scene& scene, int threads) {
  const auto t0 = std::chrono::steady_clock::now();
  DemConstants3 out;
  out.prism = constants_prism(scene);
  const Static3Options o = static3_options(scene);
  Static3Options fabric = o;  // rock bonds across the joint planes
  fabric.joint = fabric.rock;
  // The unjointed prism, the jointed ones at 0, 45 and 90 deg, and the same jointed meshes with rock bonds.
  struct Case {
    bool joints = false;
    double dip = 0;
    const Static3Options* options = nullptr;
    std::size_t mesh = 0;
  };
  std::vector<Case> cases{{false, 0.0, &o, 0}};
  if (out.prism.joints) {
    for (double dip : {0.0, 45.0, 90.0}) cases.push_back({true, dip, &o, cases.size()});
    for (std::size_t k = 1; k <= 3; ++k) cases.push_back({true, cases[k].dip, &fabric, k});
  }
  std::vector<TetMesh> meshes;
  std::vector<double> seconds;
  for (const Case& c : cases) {
    if (c.mesh < meshes.size()) continue;
    const auto t = std::chrono::steady_clock::now();
    SpecimenGeometry3 g = out.prism;
    g.joints = c.joints, g.set1.dip_deg = c.dip;
    meshes.push_back(mesh_specimen3(g, scene.mesh.size));
    seconds.push_back(since(t));
  }
  std::vector<VirtualTest3> tests(cases.size());
  const int workers = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  parallel_map(cases.size(), workers, [&](std::size_t k) {
    const auto t = std::chrono::steady_clock::now();
    const Static3Result r = solve_static3(meshes[cases[k].mesh], *cases[k].options);
    const double mesh_seconds = cases[k].options == &o ? seconds[cases[k].mesh] : 0.0;
    tests[k] = virtual_test3(r, cases[k].dip, mesh_seconds + since(t));
  });
  out.intact = tests[0];
  const theory::TIConstants rock = isotropic_constants3(out.intact);
  out.dem = rock;
  double d_mean = 0;
  if (out.prism.joints) {
    out.tests.assign(tests.begin() + 1, tests.begin() + 4);
    out.fabric_tests.assign(tests.begin() + 4, tests.end());
    out.dem = ti_constants3(out.tests[0], out.tests[1], out.tests[2]);
    out.fabric = ti_constants3(out.fabric_tests[0], out.fabric_tests[1], out.fabric_tests[2]);
    d_mean = out.tests[0].joint_d_mean;
  }
  out.goodman = goodman_estimate(scene, rock, d_mean);
  if (out.prism.joints)
    out.goodman_fabric = theory::add_joints(out.fabric, out.goodman.k_n, out.goodman.k_s, out.goodman.spacing);
  out.seconds = since(t0);
  return out;
}

}  // namespace rbdem::compare
