// The elastic gate's report: elastic.json and the readable table. See elastic_gate.hpp.
#include "compare/gate/elastic_gate.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dem/version.hpp"

namespace rbdem::compare {

namespace {

std::string gpa(double v) { return std::isfinite(v) ? fmt::format("{:8.2f}", v / 1e9) : fmt::format("{:>8}", "-"); }
std::string pct(double v) { return std::isfinite(v) ? fmt::format("{:+7.2f}", 100.0 * v) : fmt::format("{:>7}", "-"); }

nlohmann::json constants_json(const theory::TIConstants& c) {
  return {{"E", c.E}, {"nu", c.nu}, {"E_prime", c.E_prime}, {"nu_prime", c.nu_prime}, {"G_prime", c.G_prime}};
}

// NaN is not JSON: write null.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// The DEM-measured, Goodman's and the intact constants (constants.dem, .goodman, .intact).
nlohmann::json constants_section(const ElasticReport& r) {
  auto dem = constants_json(r.dem.constants);
  dem["a11"] = r.dem.a.a11, dem["a22"] = r.dem.a.a22, dem["a12"] = r.dem.a.a12, dem["a66"] = r.dem.a.a66;
  dem["fit_residual"] = r.dem.residual;
  dem["fit_max_residual"] = r.dem.max_residual;
  dem["fit_condition"] = number(r.dem.condition);
  dem["fit_betas_deg"] = r.fit_betas;
  dem["admissible"] = r.dem.admissible;
  auto good = constants_json(r.goodman.constants);
  good["E_r"] = r.goodman.E_r, good["nu_r"] = r.goodman.nu_r;
  good["k_n"] = number(r.goodman.k_n), good["k_s"] = number(r.goodman.k_s);
  good["spacing"] = r.goodman.spacing, good["d_mean"] = r.goodman.d_mean;
  auto intact = constants_json(r.intact_constants);
  intact["dem_static_pa"] = r.intact.platen_modulus;
  intact["dem_gauge_pa"] = r.intact.gauge_modulus;
  nlohmann::json out = {{"dem", dem}, {"goodman", good}, {"intact", intact}};
  if (r.two_rocks) out["intact_rock2"] = constants_json(r.intact2_constants);
  return out;
}

// The joint interfaces, the homogenization indicator and Amadei's check: the structure the verdict rests on.
void add_structure(nlohmann::json& j, const ElasticReport& r) {
  const InterfaceSummary& is = r.interfaces;
  j["joint_interfaces"] = {{"k_n_mean", number(is.k_n)},  {"k_s_mean", number(is.k_s)},
                           {"c_n", is.c_n},               {"c_s", is.c_s},
                           {"interface_edges", is.edges}, {"glued_edges", is.glued},
                           {"stiffened_edges", is.stiffened}, {"note", is.note}};
  const Homogenization& h = r.homogenization;
  j["homogenization"] = {{"layers_across", number(h.layers_across)},
                         {"joints_held", h.joints_held},
                         {"contrast", number(h.contrast)},
                         {"compliance_ratio", number(h.compliance_ratio)},
                         {"indicator", number(h.indicator)},
                         {"max_indicator", h.max_indicator},
                         {"measured_error", number(h.measured_error)},
                         {"applies", h.applies},
                         {"outside", h.outside}};
  j["amadei"] = {{"applicable", r.amadei.applicable},
                 {"max_deviation", number(r.amadei.max_deviation)},
                 {"worst_beta_deg", r.amadei.worst_beta_deg},
                 {"max_fit_residual", r.amadei.max_residual_for_ti},
                 {"note", r.amadei.note}};
}

// One dip's row of angles[]: the moduli, the differences, the measurements behind them and, with fields, the
// displacements.
nlohmann::json angle_json(const ElasticAngle& a) {
  nlohmann::json e = {
      {"beta_deg", a.beta_deg},
      {"amadei_pa", a.amadei},
      {"dem_static_pa", a.dem_static},
      {"fe_pa", number(a.fe)},
      {"fe_goodman_pa", number(a.fe_goodman)},
      {"fe_joints_pa", number(a.fe_joints)},
      {"fe_joints_platen_pa", number(a.fe_joints_platen)},
      {"rock_gauge_pa", number(a.rock_test.S22 != 0 ? a.rock_test.gauge_modulus : ElasticAngle::nan)},
      {"rock_E", a.rock_constants.E},
      {"rock_nu", a.rock_constants.nu},
      {"rock_open_linear_parts", a.rock_test.open_bonds},
      {"rock2_E", a.rock2_constants.E},
      {"rock2_nu", a.rock2_constants.nu},
      {"interbedded_pa", number(a.interbedded)},
      {"dem_gauge_vs_interbedded", number(a.dem_gauge / a.interbedded - 1.0)},
      {"fe_joints_intact_platen_pa", number(a.fe_joints_intact_platen)},
      {"homogenized_pa", number(a.homogenized)},
      {"homogenization_error", number(a.homogenization_error())},
      {"dem_linear_pa", number(a.dem_linear)},
      {"fe_joints_linear_pa", number(a.fe_joints_linear)},
      {"dem_gauge_pa", a.dem_gauge},
      {"amadei_goodman_pa", a.amadei_goodman},
      {"dem_gauge_vs_fe_joints", number(a.deviation_joints(GateMeasure::gauge))},
      {"dem_static_vs_fe_joints_platen", number(a.deviation_joints(GateMeasure::platen))},
      {"fe_joints_vs_amadei", number(a.fe_joints / a.amadei - 1.0)},
      {"fe_joints_platen_vs_fe_goodman", number(a.fe_joints_platen / a.fe_goodman - 1.0)},
      {"dem_static_vs_amadei", a.deviation(GateMeasure::platen)},
      {"dem_gauge_vs_amadei", a.deviation(GateMeasure::gauge)},
      {"fe_vs_amadei", number(a.fe / a.amadei - 1.0)},
      {"fe_goodman_vs_amadei", number(a.fe_goodman / a.amadei - 1.0)},
      {"dem_static_vs_fe_goodman", number(a.dem_static / a.fe_goodman - 1.0)},
      {"S12", a.test.S12},
      {"S22", a.test.S22},
      {"S26", a.test.S26},
      {"gauge_blocks", a.test.gauge.blocks},
      {"gauge_misfit", a.test.gauge.misfit},
      {"fe_joints_gauge_misfit", number(a.fe_joints_gauge.misfit)},
      {"blocks", a.test.blocks},
      {"bonds", a.test.bonds},
      {"joint_bonds", a.test.joint_bonds},
      {"interface_edges", a.interface_edges},
      {"glued_edges", a.glued_edges},
      {"fe_joints_dofs", a.fe_joints_dofs},
      {"open_linear_parts", a.test.open_bonds},
      {"open_joint_linear_parts", a.test.open_joint_bonds},
      {"fe_joints_open_edges", a.fe_joints_open_edges},
      {"fe_joints_state_solves", a.fe_joints_state_solves},
      {"fe_joints_states_settled", a.fe_joints_states_settled},
      {"sliding_linear_parts", a.test.sliding_bonds},
      {"static_solve_seconds", a.test.solve_seconds},
      {"fe_seconds", a.fe_seconds},
      {"fe_joints_seconds", a.fe_joints_seconds},
  };
  if (std::isfinite(a.field_l2)) e["field_l2"] = a.field_l2;
  if (std::isfinite(a.field_l2_joints)) e["field_l2_joints"] = a.field_l2_joints;
  if (!a.fields.x.empty()) {
    e["fields"] = {{"x", a.fields.x}, {"y", a.fields.y}, {"dem_ux", a.fields.dem_ux}, {"dem_uy", a.fields.dem_uy}};
    if (!a.fields.fe_ux.empty()) e["fields"]["fe_ux"] = a.fields.fe_ux, e["fields"]["fe_uy"] = a.fields.fe_uy;
    if (!a.fields.fe_joints_ux.empty())
      e["fields"]["fe_joints_ux"] = a.fields.fe_joints_ux, e["fields"]["fe_joints_uy"] = a.fields.fe_joints_uy;
  }
  return e;
}

// gate{}: the verdict and the maxima of every comparison.
nlohmann::json gate_json(const ElasticReport& r) {
  const GateVerdict& g = r.gate;
  return {{"tolerance", g.tolerance},
           {"passed", g.passed},
           {"comparison", g.comparison},
           {"measure", measure_name(g.measure)},
           {"max_deviation", number(g.max_deviation)},
           {"worst_beta_deg", g.worst_beta_deg},
           {"max_deviation_dem_gauge_vs_fe_joints", number(g.max_deviation_joints)},
           {"worst_beta_fe_joints_deg", g.worst_beta_joints_deg},
           {"max_deviation_linear", number(g.max_deviation_linear)},
           {"linear_check_run", r.linear_check_run},
           {"linear_check_sliding", r.linear_check_sliding},
           {"max_deviation_dem_static_vs_fe_joints_platen", number(g.max_deviation_joints_platen)},
           {"max_deviation_dem_static", number(g.max_deviation_static)},
           {"max_deviation_dem_gauge", number(g.max_deviation_gauge)},
           {"message", g.message},
           {"reason", g.reason}};
}

// Layers of two rocks: each dip's rocks of the layers (FEj gives each layer its rock's constants) and Salamon's
// interbedded medium beside the DEM.
std::string two_rocks_table(const ElasticReport& r) {
  std::string s = "  two rocks: beta, rock and rock2 of the layers (E GPa, nu), Salamon + Amadei (interbedded, GPa), "
                  "DEM gauge vs it (%), FEj vs it (%)\n";
  for (const auto& a : r.angles)
    s += fmt::format("  {:5g}  {} {:.3f}  {} {:.3f}  {}  {}  {}\n", a.beta_deg, gpa(a.rock_constants.E),
                     a.rock_constants.nu, gpa(a.rock2_constants.E), a.rock2_constants.nu, gpa(a.interbedded),
                     pct(a.dem_gauge / a.interbedded - 1.0), pct(a.fe_joints / a.interbedded - 1.0));
  const auto& c2 = r.intact2_constants;
  s += fmt::format("  intact rock2: E {:.2f} GPa, nu {:.3f} (intact rock E {:.2f} GPa, nu {:.3f})\n", c2.E / 1e9,
                   c2.nu, r.intact_constants.E / 1e9, r.intact_constants.nu);
  return s;
}

}  // namespace

nlohmann::json elastic_json(const ElasticReport& r, const Scene& scene) {
  nlohmann::json j;
  j["version"] = version_text();
  j["constants"] = constants_section(r);
  add_structure(j, r);
  j["angles"] = nlohmann::json::array();
  for (const auto& a : r.angles) j["angles"].push_back(angle_json(a));
  j["gate"] = gate_json(r);
  j["model"] = scene.specimen.model;
  j["platens"] = "frictionless";  // whatever loading.platen_friction says: Amadei's and the FE's condition
  j["fe_available"] = r.fe_available;
  j["timing"] = {{"total_seconds", r.seconds},
                 {"dem_seconds", r.dem_seconds},
                 {"fe_seconds", r.fe_seconds},
                 {"fe_joints_seconds", r.fe_joints_seconds},
                 {"linear_check_seconds", r.linear_check_seconds}};
  j["scene"] = scene_json(scene);
  return j;
}

std::string elastic_table(const ElasticReport& r) {
  const GateVerdict& g = r.gate;
  const bool lin = r.linear_check_run;
  std::string s = fmt::format(
      "elastic gate: DEM static moduli vs the FE model with the joints as interfaces (FEj), Amadei with the "
      "DEM-measured constants and the homogenized FE ({}, mesh {:g} mm, frictionless platens)\n",
      r.plane == theory::Plane::strain ? "plane strain" : "plane stress", 1e3 * r.mesh_size);
  s += fmt::format(" beta DEM gauge      FEj  gau-FEj  DEM stat FEj plat stat-FEjp     rock |   Amadei gauge-Am FE Goodm"
                   "  homog |{} L2 FE L2 FEj\n",
                   lin ? "  DEM lin  FEj lin  lin-FEj |" : "");
  s += fmt::format("  deg      GPa      GPa        %       GPa      GPa         %      GPa |      GPa        %      GPa"
                   "      % |{}     %      %\n",
                   lin ? "      GPa      GPa        % |" : "");
  auto l2 = [](double v) { return std::isfinite(v) ? fmt::format("{:6.2f}", 100.0 * v) : fmt::format("{:>6}", "-"); };
  for (const auto& a : r.angles) {
    const double rock = a.rock_test.S22 != 0 ? a.rock_test.gauge_modulus : std::numeric_limits<double>::quiet_NaN();
    s += fmt::format("{:5g} {} {}  {}  {} {}   {} {} | {}  {} {} {} |{}{} {}{}\n", a.beta_deg, gpa(a.dem_gauge),
                     gpa(a.fe_joints), pct(a.deviation_joints(GateMeasure::gauge)), gpa(a.dem_static),
                     gpa(a.fe_joints_platen), pct(a.deviation_joints(GateMeasure::platen)), gpa(rock),
                     gpa(a.amadei), pct(a.deviation(GateMeasure::gauge)), gpa(a.fe_goodman),
                     pct(a.homogenization_error()),
                     lin ? fmt::format(" {} {}  {} |", gpa(a.dem_linear), gpa(a.fe_joints_linear),
                                       pct(a.dem_linear / a.fe_joints_linear - 1.0))
                         : "",
                     l2(a.field_l2), l2(a.field_l2_joints),
                     a.beta_deg == g.worst_beta_deg && !g.passed ? "  <- worst" : "");
  }
  s += "  (rock: the DEM gauge modulus of the same mesh with rock bonds on the joints, the layers of FEj; homog: the "
       "FE model with the joints on the intact rock over Goodman's homogenized modulus, platens)\n";
  if (r.two_rocks) s += two_rocks_table(r);
  const auto& c = r.dem.constants;
  s += fmt::format("DEM constants:     E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa "
                   "(virtual tests at {} deg, weighted fit residual {:.2f} %, condition {:.3g}{})\n",
                   c.E / 1e9, c.nu, c.E_prime / 1e9, c.nu_prime, c.G_prime / 1e9, fmt::join(r.fit_betas, "/"),
                   100.0 * r.dem.residual, r.dem.condition, r.dem.admissible ? "" : ", NOT admissible");
  const auto& gc = r.goodman.constants;
  s += fmt::format("Goodman constants: E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa "
                   "(intact E_r {:.2f} GPa, nu_r {:.3f}; k_n {:.3g} Pa/m, k_s {:.3g} Pa/m, s {:g} m)\n",
                   gc.E / 1e9, gc.nu, gc.E_prime / 1e9, gc.nu_prime, gc.G_prime / 1e9, r.goodman.E_r / 1e9,
                   r.goodman.nu_r, r.goodman.k_n, r.goodman.k_s, r.goodman.spacing);
  const InterfaceSummary& is = r.interfaces;
  if (r.fe_available)
    s += fmt::format("FE with joints:    {} joint edges over the dips as interfaces, {} glued; per edge k_n = 1/(d c_n), "
                     "k_s = 1/(d c_s), c_n = {:.3g} 1/Pa, c_s = {:.3g} 1/Pa: mean k_n {:.3g} Pa/m, k_s {:.3g} Pa/m; "
                     "{:.2f} s of FE with joints\n",
                     is.edges, is.glued, is.c_n, is.c_s, is.k_n, is.k_s, r.fe_joints_seconds);
  if (!is.note.empty()) s += "  " + is.note + "\n";
  const Homogenization& h = r.homogenization;
  s += fmt::format("homogenization:    {:.3g} layers across (W/s), {} joints held, contrast E*_r/E*_j {:.3g}, joint "
                   "compliance {:.3g} x the rock's over one spacing: indicator {:.3g} ({} <= {:.3g}){}\n",
                   h.layers_across, h.joints_held, h.contrast, h.compliance_ratio, h.indicator,
                   h.applies ? "applies," : "does not apply, not", h.max_indicator,
                   std::isfinite(h.measured_error)
                       ? fmt::format("; measured: {:.2f} % (homog column)", 100.0 * h.measured_error)
                       : "");
  if (!h.outside.empty()) s += "  " + h.outside + ": the gate compares the DEM with the FE model with the joints\n";
  s += fmt::format("gate ({} vs {}): {}\n", measure_name(g.measure), g.comparison, g.message);
  if (!g.passed) s += "  " + g.reason + "\n";
  return s;
}

}  // namespace rbdem::compare
