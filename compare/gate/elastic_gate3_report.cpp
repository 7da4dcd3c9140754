// The 3D elastic gate's report: elastic.json and the readable table. See elastic_gate3.hpp.
#include <cmath>

#include <fmt/format.h>

#include "compare/gate/elastic_gate3.hpp"
#include "dem/version.hpp"

namespace rbdem::compare {

namespace {

std::string gpa(double v) { return std::isfinite(v) ? fmt::format("{:8.2f}", v / 1e9) : fmt::format("{:>8}", "-"); }
std::string pct(double v) { return std::isfinite(v) ? fmt::format("{:+7.2f}", 100.0 * v) : fmt::format("{:>7}", "-"); }
std::string ratio(double v) { return std::isfinite(v) ? fmt::format("{:6.3f}", v) : fmt::format("{:>6}", "-"); }
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json constants_json(const theory::TIConstants& c) {
  return {{"E", c.E}, {"nu", c.nu}, {"E_prime", c.E_prime}, {"nu_prime", c.nu_prime}, {"G_prime", c.G_prime}};
}

nlohmann::json test_json(const VirtualTest3& t) {
  return {{"dip_deg", t.dip_deg},
          {"modulus_pa", t.modulus},
          {"platen_modulus_pa", t.platen_modulus},
          {"poisson_strike", t.poisson_strike},
          {"poisson_dip", t.poisson_dip},
          {"blocks", t.blocks},
          {"joint_bonds", t.joint_bonds},
          {"seconds", t.seconds}};
}

nlohmann::json constants_section(const Elastic3Report& r) {
  const DemConstants3& c = r.constants;
  auto dem = constants_json(c.dem);
  dem["admissible"] = c.dem.admissible();
  dem["fit_betas_deg"] = nlohmann::json::array();
  dem["virtual_tests"] = nlohmann::json::array();
  for (const auto& t : c.tests) dem["fit_betas_deg"].push_back(t.dip_deg), dem["virtual_tests"].push_back(test_json(t));
  dem["prism"] = {{"width", c.prism.width}, {"depth", c.prism.depth}, {"height", c.prism.height}};
  auto good = constants_json(c.goodman.constants);
  good["E_r"] = c.goodman.E_r, good["nu_r"] = c.goodman.nu_r;
  good["k_n"] = number(c.goodman.k_n), good["k_s"] = number(c.goodman.k_s);
  good["spacing"] = c.goodman.spacing, good["d_mean"] = c.goodman.d_mean;
  auto intact = constants_json(isotropic_constants3(c.intact));
  intact["dem_static_pa"] = c.intact.modulus;
  intact["virtual_test"] = test_json(c.intact);
  nlohmann::json sections = {{"dem", dem}, {"goodman", good}, {"intact", intact}};
  if (!c.fabric_tests.empty()) {
    auto rock = constants_json(c.fabric);
    rock["virtual_tests"] = nlohmann::json::array();
    for (const auto& t : c.fabric_tests) rock["virtual_tests"].push_back(test_json(t));
    auto jm = constants_json(c.goodman_fabric);
    jm["rock"] = rock;
    sections["goodman_jointed_mesh"] = jm;
  }
  return sections;
}

nlohmann::json angle_json(const Elastic3Angle& a) {
  return {{"beta_deg", a.beta_deg},
          {"amadei_pa", a.amadei},
          {"amadei_goodman_pa", a.amadei_goodman},
          {"amadei_goodman_jointed_mesh_pa", number(a.amadei_goodman_fabric)},
          {"dem_static_vs_amadei_goodman_jointed_mesh", number(a.dem_static / a.amadei_goodman_fabric - 1.0)},
          {"dem_static_pa", a.dem_static},
          {"dem_platen_pa", a.dem_platen},
          {"fe_pa", number(a.fe)},
          {"fe_platen_pa", number(a.fe_platen)},
          {"fe_goodman_pa", number(a.fe_goodman)},
          {"fe_joints_pa", number(a.fe_joints)},
          {"fe_joints_platen_pa", number(a.fe_joints_platen)},
          {"dem_static_vs_fe_joints", number(a.dem_static / a.fe_joints - 1.0)},
          {"dem_static_vs_fe", number(a.deviation_fe())},
          {"dem_static_vs_amadei", a.deviation_amadei()},
          {"fe_vs_amadei", number(a.fe / a.amadei - 1.0)},
          {"dem_static_vs_fe_goodman", number(a.dem_static / a.fe_goodman - 1.0)},
          {"poisson_strike", {{"dem", a.dem_poisson_strike}, {"amadei", a.amadei_poisson_strike},
                              {"fe", number(a.fe_poisson_strike)}, {"fe_joints", number(a.fe_joints_poisson_strike)}}},
          {"poisson_dip", {{"dem", a.dem_poisson_dip}, {"amadei", a.amadei_poisson_dip},
                           {"fe", number(a.fe_poisson_dip)}, {"fe_joints", number(a.fe_joints_poisson_dip)}}},
          {"blocks", a.blocks},
          {"bonds", a.bonds},
          {"joint_bonds", a.joint_bonds},
          {"dofs", a.dofs},
          {"fe_dofs", a.fe_dofs},
          {"mesh_seconds", a.mesh_seconds},
          {"static_solve_seconds", a.dem_seconds},
          {"fe_seconds", a.fe_seconds},
          {"fe_joints_seconds", a.fe_joints_seconds}};
}

}  // namespace

nlohmann::json elastic3_json(const Elastic3Report& r, const Scene& scene) {
  nlohmann::json j;
  j["version"] = version_text();
  j["dimension"] = 3;
  j["shape"] = r.shape;
  j["mesh_size"] = r.mesh_size;
  j["dip_direction_deg"] = r.dip_direction_deg;
  j["constants"] = constants_section(r);
  j["angles"] = nlohmann::json::array();
  for (const auto& a : r.angles) j["angles"].push_back(angle_json(a));
  const Gate3Verdict& g = r.gate;
  j["gate"] = {{"tolerance", g.tolerance},       {"passed", g.passed},
               {"comparison", g.comparison},     {"measure", "dem_static"},
               {"max_deviation", g.max_deviation}, {"worst_beta_deg", g.worst_beta_deg},
               {"max_deviation_dem_static_vs_amadei", g.max_deviation_amadei},
               {"message", g.message},           {"reason", g.reason}};
  j["platens"] = "frictionless";
  j["fe_available"] = r.fe_available;
  j["timing"] = {{"total_seconds", r.seconds},
                 {"constants_seconds", r.constants_seconds},
                 {"mesh_seconds", r.mesh_seconds},
                 {"dem_seconds", r.dem_seconds},
                 {"fe_seconds", r.fe_seconds},
                 {"fe_joints_seconds", r.fe_joints_seconds}};
  j["scene"] = scene_json(scene);
  return j;
}

std::string elastic3_table(const Elastic3Report& r) {
  std::string s = fmt::format(
      "elastic gate (3D {}, mesh {:g} mm, dip direction {:g} deg, frictionless platens): DEM static moduli vs the FE "
      "twin with the DEM's constants (FE), Amadei and the FE twin with Goodman's constants\n",
      r.shape, 1e3 * r.mesh_size, r.dip_direction_deg);
  s += " beta DEM stat       FE  DEM-FE   Amadei DEM-Am FE Goodm    Gd jm DEM-Gd FE jnts DEM-FEj | nu_strike DEM  Am    "
       "FE | nu_dip DEM   Am    FE | blocks\n";
  s += "  deg      GPa      GPa       %      GPa      %      GPa      GPa      %      GPa       % |\n";
  for (const auto& a : r.angles)
    s += fmt::format("{:5g} {} {} {} {} {} {} {} {} {} {} |    {} {} {} | {} {} {} | {}{}\n", a.beta_deg,
                     gpa(a.dem_static), gpa(a.fe), pct(a.deviation_fe()), gpa(a.amadei), pct(a.deviation_amadei()),
                     gpa(a.fe_goodman), gpa(a.amadei_goodman_fabric), pct(a.dem_static / a.amadei_goodman_fabric - 1.0),
                     gpa(a.fe_joints), pct(a.dem_static / a.fe_joints - 1.0),
                     ratio(a.dem_poisson_strike), ratio(a.amadei_poisson_strike), ratio(a.fe_poisson_strike),
                     ratio(a.dem_poisson_dip), ratio(a.amadei_poisson_dip), ratio(a.fe_poisson_dip), a.blocks,
                     a.beta_deg == r.gate.worst_beta_deg && !r.gate.passed ? "  <- worst" : "");
  const auto& c = r.constants.dem;
  s += fmt::format("DEM constants:     E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa (virtual "
                   "tests on the {:g} x {:g} x {:g} mm prism at 0/45/90 deg{})\n",
                   c.E / 1e9, c.nu, c.E_prime / 1e9, c.nu_prime, c.G_prime / 1e9, 1e3 * r.constants.prism.width,
                   1e3 * r.constants.prism.depth, 1e3 * r.constants.prism.height,
                   c.admissible() ? "" : ", NOT admissible");
  const auto& g = r.constants.goodman;
  s += fmt::format("Goodman constants: E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa (unjointed "
                   "E_r {:.2f} GPa, nu_r {:.3f}; k_n {:.3g} Pa/m, k_s {:.3g} Pa/m at d_mean {:.3g} mm, s {:g} m)\n",
                   g.constants.E / 1e9, g.constants.nu, g.constants.E_prime / 1e9, g.constants.nu_prime,
                   g.constants.G_prime / 1e9, g.E_r / 1e9, g.nu_r, g.k_n, g.k_s, 1e3 * g.d_mean, g.spacing);
  if (!r.constants.fabric_tests.empty()) {
    const auto& f = r.constants.fabric;
    const auto& j = r.constants.goodman_fabric;
    s += fmt::format("Goodman on the jointed mesh: E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa (its "
                     "rock, rock bonds across the planes: E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} "
                     "GPa)\n",
                     j.E / 1e9, j.nu, j.E_prime / 1e9, j.nu_prime, j.G_prime / 1e9, f.E / 1e9, f.nu, f.E_prime / 1e9,
                     f.nu_prime, f.G_prime / 1e9);
    s += fmt::format("DEM / Goodman - 1: E {} %, nu {} %, E' {} %, nu' {} %, G' {} % (on the jointed mesh's rock); E' {} "
                     "%, G' {} % (on the unjointed rock)\n",
                     pct(c.E / j.E - 1.0), pct(c.nu / j.nu - 1.0), pct(c.E_prime / j.E_prime - 1.0),
                     pct(c.nu_prime / j.nu_prime - 1.0), pct(c.G_prime / j.G_prime - 1.0),
                     pct(c.E_prime / g.constants.E_prime - 1.0), pct(c.G_prime / g.constants.G_prime - 1.0));
  }
  s += fmt::format("gate (dem_static vs {}): {}\n", r.gate.comparison, r.gate.message);
  if (!r.gate.passed) s += "  " + r.gate.reason + "\n";
  return s;
}

}  // namespace rbdem::compare
