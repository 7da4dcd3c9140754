// Brazilian disc cases: the stress at the centre of a disc under two opposite diametral forces, below failure, from
// the DEM (static solve), from the deal.II disc model on the same mesh (continuum/fe_disc.hpp) and from the closed
// forms (theory/disc.hpp; docs/theory.md, section 9): Hondros for the isotropic disc, Claesson & Bohloli's
// approximation for the layered one. The measurements are compare/verify/disc_measures.hpp.
//
// Like for like: the FE disc and the closed forms are linear elastic, and the DEM as it runs is not (a bond's
// linear part carries compression only, so a bonded edge is about twice as stiff in compression as in tension).
// The DEM with every linear part held closed is the linear model they describe: those cases gate. The DEM as it
// runs (as the failure runs load it) is reported beside them as information, with its count of open linear parts
// and its deviation from the same references (the cases *_as_run).
//
// The DEM's stress is a volume average (Love-Weber over the blocks whose centroid lies within r_avg of the centre,
// dem/measure.hpp), so it is compared with the mean of the same field over the same circle: Hondros's exact mean for
// the isotropic disc, the FE's mean over the same radius for the layered one. The closed form of the layered disc
// is a point value at the centre; the FE gives both, so the DEM's centre value is its mean times the FE's ratio of
// centre to mean (a correction of about 4 % at r_avg = R / 5, the curvature of the field).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "compare/verify/disc_measures.hpp"
#include "compare/verify/verify.hpp"
#include "dem/specimen_mesh.hpp"
#include "theory/disc.hpp"

namespace rbdem::verify {

namespace {

constexpr double average_fraction = 0.2;  // r_avg / R; the table of docs/verification.md shows 0.1 to 0.5

// The isotropic disc at two mesh sizes: the DEM with its linear parts held closed (gated) or as it runs, pushed
// and pulled (informational).
CaseResult hondros(bool as_run) {
  CaseResult r;
  r.checks = as_run ? "the DEM as it runs (linear parts in compression only): its mean stress over the central "
                      "circle r <= R/5 of an unjointed disc under diametral point loads, pushed and pulled, at two "
                      "mesh sizes, with its count of open linear parts"
                    : "the DEM with every linear part held closed: its mean stress over the central circle r <= R/5 "
                      "of an unjointed disc under diametral point loads, at two mesh sizes";
  r.reference = "Hondros's isotropic disc, averaged over the same circle (docs/theory.md, section 9)";
  r.unit = "MPa";
  r.error_definition = "max over the mesh sizes of |sigma_xx / ref - 1| and |sigma_yy / ref - 1| (xx: the tension "
                       "across the loaded diameter, 2P/(pi D t) at the centre; yy: -3 times that)";
  double worst = 0;
  std::size_t blocks = 0;
  for (double h : {0.002, 0.001}) {
    Scene s = disc_scene(Scene{}, false, 0);
    s.mesh.size = h;
    const TriMesh mesh = make_mesh(s);
    const double P = unit_disc_load(s);
    const DemDisc d = dem_disc(s, mesh, P, average_fraction, !as_run);
    const theory::DiscStress ref =
        theory::hondros_mean_stress(P, s.specimen.diameter, s.specimen.thickness, average_fraction * d.R);
    const double exx = d.mean.xx() / ref.xx - 1, eyy = d.mean.yy() / ref.yy - 1;
    worst = std::max({worst, std::abs(exx), std::abs(eyy)});
    blocks = d.blocks;
    nlohmann::json row = {{"mesh_size_m", h}, {"blocks_averaged", int(d.mean.blocks)}, {"sxx_pa", d.mean.xx()},
                          {"sxx_ref_pa", ref.xx}, {"syy_pa", d.mean.yy()}, {"syy_ref_pa", ref.yy},
                          {"sxy_pa", d.mean.xy()}, {"error_xx", exx}, {"error_yy", eyy}};
    if (as_run) {
      // The same forces reversed: a linear model flips sign; the DEM as it runs does not.
      const DemDisc pulled = dem_disc(s, mesh, -P, average_fraction, false);
      const DemDisc closed = dem_disc(s, mesh, P, average_fraction, true);
      row.update({{"open_linear_parts", d.open}, {"bonds", d.bonds}, {"vs_closed_xx", d.mean.xx() / closed.mean.xx() - 1},
                  {"pulled_sxx_pa", -pulled.mean.xx()}, {"pulled_syy_pa", -pulled.mean.yy()},
                  {"pulled_error_xx", -pulled.mean.xx() / ref.xx - 1},
                  {"pulled_error_yy", -pulled.mean.yy() / ref.yy - 1}, {"pulled_open_linear_parts", pulled.open}});
    }
    r.table.push_back(row);
    r.measured = d.mean.xx() / 1e6, r.reference_value = ref.xx / 1e6;  // the finest mesh's sigma_xx
  }
  r.error = worst;
  r.tolerance = as_run ? std::nan("") : 0.05;
  r.tolerance_source =
      as_run ? "informational: the DEM as it runs is bimodular (a linear part carries compression only) and "
               "Hondros's disc is linear; brazilian.hondros gates the like-for-like comparison. The rows give the "
               "open linear parts, the deviation from the DEM with its linear parts closed, and the forces "
               "reversed ('pulled', which a linear model would give with the sign flipped)"
             : "the agreement asked of the Brazilian protocol's stress (5 %), for the linear model that Hondros's "
               "disc describes: the DEM with its linear parts held closed (brazilian.hondros_as_run reports the "
               "DEM as it runs)";
  r.cost = fmt::format("{} static disc solves (2 mm and 1 mm, {} blocks)", as_run ? 6 : 2, blocks);
  return r;
}

CaseResult disc_hondros(const Context&) { return hondros(false); }
CaseResult disc_hondros_as_run(const Context&) { return hondros(true); }

#if RBDEM_HAVE_CONTINUUM

// The layered disc at layer angles 0, 45 and 90 deg (dips 90, 45, 0): DEM, FE with the linear DEM's constants, and
// Claesson & Bohloli with the same constants. `soft`: joints ten times softer than the paper's at 2.5 mm spacing,
// a strongly anisotropic disc (E/E' about 6.7) where the closed form's approximation is no longer exact. `quick`:
// 2 mm blocks instead of the scene's 1 mm (about 1300 blocks).
LayeredDisc measure(bool soft, bool quick) {
  Scene base;
  if (quick) base.mesh.size = 0.002;
  if (soft) {
    base.joint.effective_modulus = 5e9;
    base.joint_set.spacing = 0.0025;
  }
  return layered_disc(base, {0.0, 45.0, 90.0}, average_fraction);
}

std::string layered_cost(const LayeredDisc& d, int dem_solves) {
  return fmt::format("3 virtual tests, {} static disc solves ({:g} mm, {} blocks), 3 FE discs ({} DoFs, {:.1f} s)",
                     dem_solves, 1e3 * d.mesh_size, d.blocks, d.fe_dofs, d.fe_seconds);
}

void constants_row(CaseResult& r, const LayeredDisc& d) {
  const theory::TIConstants& c = d.constants;
  r.table.push_back({{"E_pa", c.E}, {"E_prime_pa", c.E_prime}, {"nu", c.nu}, {"nu_prime", c.nu_prime},
                     {"G_prime_pa", c.G_prime}, {"fit_residual", d.fit_residual}});
}

// The rows of the DEM with its linear parts closed (and, for the informational soft disc, the DEM as it runs).
void linear_rows(CaseResult& r, const LayeredDisc& d, bool with_as_run) {
  const double s0 = 1e6;
  for (const DiscAngle& a : d.angles) {
    nlohmann::json row = {{"layer_angle_deg", a.layer_angle_deg}, {"dip_deg", a.dip_deg},
                          {"dem_mean_factor", a.dem_mean / s0}, {"fe_mean_factor", a.fe_mean / s0},
                          {"fe_centre_factor", a.fe_centre / s0}, {"dem_centre_factor", a.dem_centre() / s0},
                          {"claesson_bohloli_factor", a.closed_form / s0}, {"dem_vs_fe", a.dem_mean / a.fe_mean - 1},
                          {"fe_vs_closed_form", a.fe_centre / a.closed_form - 1},
                          {"dem_vs_closed_form", a.dem_centre() / a.closed_form - 1}};
    if (with_as_run)
      row.update({{"dem_as_run_mean_factor", a.dem_as_run_mean / s0},
                  {"dem_as_run_vs_fe", a.dem_as_run_mean / a.fe_mean - 1}, {"open_linear_parts", a.open_as_run}});
    r.table.push_back(row);
  }
  const DiscAngle& first = d.angles.front();
  r.measured = first.dem_centre() / s0, r.reference_value = first.closed_form / s0;
}

CaseResult layered_case(bool soft, bool quick) {
  CaseResult r;
  r.checks = soft ? "the centre tension of a strongly layered disc (joints at 2.5 mm, joint modulus 5 GPa) at layer "
                    "angles 0, 45 and 90 deg: the DEM with every linear part held closed (and as it runs), FE on "
                    "the same mesh and the closed form"
                  : "the centre tension of the paper's layered disc (joints at 10 mm) at layer angles 0, 45 and 90 "
                    "deg: the DEM with every linear part held closed, FE on the same mesh and the closed form";
  r.reference = "Claesson & Bohloli's approximate centre tension of a transversely isotropic disc and the deal.II "
                "disc, both with the linear DEM's five constants fitted from static virtual tests at dips 0, 45, "
                "90 with every linear part held closed (docs/theory.md, section 9)";
  r.unit = "-";
  const LayeredDisc d = measure(soft, quick);
  linear_rows(r, d, soft);
  constants_row(r, d);
  r.error = like_for_like_error(d);
  r.error_definition = "max over the three angles of |DEM mean / FE mean - 1|, |FE centre / closed form - 1| and "
                       "|DEM centre / closed form - 1|, the DEM with its linear parts closed (measured/reference: "
                       "the factor sigma_t / (2P/(pi D t)) at layer angle 0)";
  r.tolerance = soft ? std::nan("") : 0.05;
  r.tolerance_source = soft ? "informational: the DEM's E/E' here is about 6.7, beyond the closed form's range "
                              "(its error is 14-21 % at E/E' = 4 against the converged FE, tests/test_disc.cpp), "
                              "and 2.5 mm joints in 1 mm blocks are barely a continuum; the table shows how far "
                              "each of the three is from the others, and the DEM as it runs beside them"
                            : "the agreement asked of the Brazilian protocol (5 %), like for like: the FE and the "
                              "closed form are linear, and so is the DEM with its linear parts held closed; the "
                              "closed form's own error for these constants is 0.2 % (tests/test_disc.cpp, FE "
                              "converged). brazilian.layered_disc_as_run reports the DEM as it runs";
  r.cost = layered_cost(d, 9);
  return r;
}

// The paper's layered disc as it runs (linear parts in compression only, as the failure runs load it), against
// the same references: informational.
CaseResult layered_as_run(const Context& ctx) {
  CaseResult r;
  r.checks = "the centre tension of the paper's layered disc (joints at 10 mm) at layer angles 0, 45 and 90 deg, "
             "the DEM as it runs (linear parts in compression only), pushed and pulled, with its open linear parts";
  r.reference = "the references of brazilian.layered_disc: the deal.II disc and Claesson & Bohloli with the linear "
                "DEM's constants";
  r.unit = "-";
  const LayeredDisc d = measure(false, ctx.quick);
  const double s0 = 1e6;
  double worst = 0;
  for (const DiscAngle& a : d.angles) {
    const double e_fe = a.dem_as_run_mean / a.fe_mean - 1, e_cb = a.dem_as_run_centre() / a.closed_form - 1;
    worst = std::max({worst, std::abs(e_fe), std::abs(e_cb)});
    r.table.push_back({{"layer_angle_deg", a.layer_angle_deg}, {"dip_deg", a.dip_deg},
                       {"dem_as_run_mean_factor", a.dem_as_run_mean / s0}, {"dem_closed_mean_factor", a.dem_mean / s0},
                       {"fe_mean_factor", a.fe_mean / s0}, {"claesson_bohloli_factor", a.closed_form / s0},
                       {"dem_as_run_vs_fe", e_fe}, {"dem_as_run_vs_closed_form", e_cb},
                       {"dem_as_run_vs_dem_closed", a.dem_as_run_mean / a.dem_mean - 1},
                       {"open_linear_parts", a.open_as_run}, {"bonds", d.bonds},
                       {"dem_pulled_mean_factor", a.dem_pulled_mean / s0},
                       {"dem_pulled_vs_fe", a.dem_pulled_mean / a.fe_mean - 1},
                       {"open_linear_parts_pulled", a.open_pulled}});
  }
  r.measured = d.angles.front().dem_as_run_centre() / s0, r.reference_value = d.angles.front().closed_form / s0;
  r.error = worst;
  r.error_definition = "max over the three angles of |DEM mean / FE mean - 1| and |DEM centre / closed form - 1|, "
                       "the DEM as it runs, pushed";
  r.tolerance_source = "informational: the DEM as it runs is bimodular (a linear part carries compression only, so "
                       "a bonded edge is about twice as stiff in compression as in tension) and the references are "
                       "linear; brazilian.layered_disc gates the like-for-like comparison. Reversing the forces "
                       "('pulled': a linear model only flips the signs) shows the asymmetry";
  r.cost = layered_cost(d, 9);
  return r;
}

CaseResult paper_disc(const Context& ctx) { return layered_case(false, ctx.quick); }
CaseResult soft_disc(const Context&) { return layered_case(true, false); }

#endif

}  // namespace

std::vector<CaseSpec> disc_cases() {
  std::vector<CaseSpec> cases{make_case("brazilian.hondros", true, disc_hondros),
                              make_case("brazilian.hondros_as_run", true, disc_hondros_as_run)};
#if RBDEM_HAVE_CONTINUUM
  cases.push_back(make_case("brazilian.layered_disc", true, paper_disc));
  cases.push_back(make_case("brazilian.layered_disc_as_run", true, layered_as_run));
  cases.push_back(make_case("brazilian.strongly_layered_disc", false, soft_disc));
#endif
  return cases;
}

}  // namespace rbdem::verify
