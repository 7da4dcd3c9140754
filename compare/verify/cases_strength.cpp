// Strength cases (full run only): the default dip study against Jaeger's plane of weakness (docs/theory.md, section 4),
// reported with the difference, not forced to agree.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "theory/elasticity.hpp"
#include "compare/verify/confined.hpp"
#include "compare/verify/verify.hpp"
#include "study/study.hpp"

namespace rbdem::verify {

namespace {

struct DipStudy {
  std::vector<study::CaseResult> results;
  study::GroupSummary group;
  double seconds = 0;
  long steps = 0;
};

// The seven-dip study of the main job, run once per process into <out>/strength (resumable like any sweep).
const DipStudy& dip_study(const Context& ctx) {
  static std::optional<DipStudy> cached;
  if (cached) return *cached;
  const Scene scene;
  const study::StudySpec spec = study::dip_study(scene, "verify_dips");
  const std::vector<study::Case> cases = study::expand(spec);
  const std::filesystem::path out = ctx.out / "strength";
  std::filesystem::create_directories(out);
  if (ctx.log) ctx.log("verify: running the default dip study (seven UCS runs) into " + out.string());
  const auto t0 = std::chrono::steady_clock::now();
  DipStudy d;
  d.results = study::run_cases(cases, out, study::SweepOptions{});
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  d.group = study::write_tables(d.results, out).front();
  for (const auto& r : d.results) d.steps += r.summary["steps"].get<long>();
  cached = std::move(d);
  return *cached;
}

CaseResult min_angle(const Context& ctx) {
  CaseResult r;
  r.checks = "the dip of the strength minimum of the default study (dips 0, 15, ..., 90)";
  r.reference = "Jaeger's plane of weakness: 45 + phi_j / 2 (docs/theory.md, section 4), on the same dip grid";
  r.unit = "deg";
  const DipStudy& d = dip_study(ctx);
  r.measured = d.group.min_beta_deg;
  r.reference_value = d.group.jaeger_min_beta_deg;
  r.error = std::abs(r.measured - r.reference_value);
  r.error_definition = "|beta_min - beta_min,Jaeger| in degrees";
  r.tolerance = 15;
  r.tolerance_source = "the dip grid's spacing (15 deg): a minimum one grid step away is within sampling";
  r.cost = fmt::format("7 UCS runs at 1 mm, {} steps, {:.0f} s", d.steps, d.seconds);
  r.table.push_back({{"min_strength_pa", d.group.min_strength_pa}, {"jaeger_min_pa", d.group.jaeger_min_pa}});
  return r;
}

CaseResult jaeger_curve(const Context& ctx) {
  CaseResult r;
  r.checks = "the strength-versus-dip curve of the default study and its anisotropy ratio";
  r.reference = "Jaeger's strength with the bonded joint's envelope and the measured 90-deg strength (docs/theory.md, section 4)";
  r.unit = "-";
  const DipStudy& d = dip_study(ctx);
  double s90 = d.group.strength_90_pa, worst = 0, jmin = 1e300;
  for (const auto& c : d.results) {
    const double p = c.summary["peak_stress_pa"].get<double>();
    const double j = study::jaeger_for(c.c.scene, c.c.beta, s90);
    jmin = std::min(jmin, j);
    worst = std::max(worst, std::abs(p / j - 1.0));
    r.table.push_back({{"beta_deg", c.c.beta}, {"peak_pa", p}, {"jaeger_pa", j}, {"difference", p / j - 1.0},
                       {"failure_mode", c.summary["failure_mode"]}});
  }
  r.measured = d.group.anisotropy_ratio;
  r.reference_value = s90 / jmin;
  r.error = worst;
  r.error_definition = "max over dips |sigma / sigma_Jaeger - 1| (measured/reference: anisotropy ratios)";
  r.tolerance_source = "informational: Jaeger assumes a uniform stress and a joint that slips at once; the DEM's "
                       "joints fail progressively from the platen corners (docs/studies.md)";
  r.cost = fmt::format("the same 7 runs ({:.0f} s)", d.seconds);
  return r;
}

// Confined compression at two confinements (0 and 10 MPa) at a slip dip (60 deg) and an intact one (90 deg), run
// once per process into <out>/confined.
constexpr int confined_realizations = 5;

struct ConfinedStudy {
  std::vector<study::Envelope> envelopes;
  std::vector<double> slopes_60;  // per mesh at 60 deg: (sigma_1 at 10 MPa - at 0) / 10 MPa
  double seconds = 0;
  long steps = 0;
};

const ConfinedStudy& confined_study(const Context& ctx) {
  static std::optional<ConfinedStudy> cached;
  if (cached) return *cached;
  // 60 deg on five meshes (the slope is compared with Jaeger's: one mesh scatters by about 1.3 %), 90 deg on one
  // (its intact envelope is reported, with no closed form to meet).
  study::StudySpec spec = confined_spec(Scene{}, "verify_confined");
  spec.dips = {60};
  spec.realizations = confined_realizations;
  std::vector<study::Case> cases = study::expand(spec);
  spec.dips = {90};
  spec.realizations = 1;
  for (auto& c : study::expand(spec)) cases.push_back(std::move(c));
  const std::filesystem::path out = ctx.out / "confined";
  std::filesystem::create_directories(out);
  if (ctx.log)
    ctx.log(fmt::format("verify: running confined compression at 60 deg ({} meshes) and 90 deg, sigma_3 = 0 and 10 "
                        "MPa, into {}", confined_realizations, out.string()));
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = study::run_cases(cases, out, study::SweepOptions{});
  ConfinedStudy c;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& r : results) c.steps += r.summary["steps"].get<long>();
  std::map<int, std::array<double, 2>> by_mesh;  // mesh seed -> peak at 0 and at 10 MPa, 60 deg
  for (const auto& r : results)
    if (r.c.beta == 60.0)
      by_mesh[r.c.scene.mesh.seed][r.c.scene.loading.confining_pressure > 0 ? 1 : 0] =
          r.summary["peak_stress_pa"].get<double>();
  for (const auto& [seed, p] : by_mesh) c.slopes_60.push_back((p[1] - p[0]) / 10e6);
  c.envelopes = study::write_envelopes(results, out);
  cached = std::move(c);
  return *cached;
}

CaseResult triaxial_slope(const Context& ctx) {
  CaseResult r;
  r.checks = "the slope d sigma_1 / d sigma_3 of confined compression at beta = 60 deg (sliding on the joints) "
             "between sigma_3 = 0 and 10 MPa, from the mean peaks of five meshes";
  r.reference = "Jaeger under confinement: 1 + 2 mu / ((1 - mu cot beta) sin 2 beta), mu of the bonded joint's "
                "envelope (docs/theory.md, section 4)";
  r.unit = "-";
  const ConfinedStudy& c = confined_study(ctx);
  const auto or_null = [](bool has, const nlohmann::json& value) { return has ? value : nlohmann::json(nullptr); };
  for (const auto& e : c.envelopes) {
    r.table.push_back({{"beta_deg", e.beta_deg}, {"points", e.points}, {"slope_0_10", e.slope_0_10},
                       {"slope_0_10_se", or_null(std::isfinite(e.slope_0_10_se), e.slope_0_10_se)},
                       {"intercept_pa", e.intercept_pa}, {"friction_deg", e.friction_deg},
                       {"cohesion_pa", e.cohesion_pa}, {"jaeger_slope", or_null(e.slip_range, e.jaeger_slope)},
                       {"slopes_per_mesh", or_null(e.beta_deg == 60.0, c.slopes_60)}});
    if (e.beta_deg == 60.0) r.measured = e.slope_0_10, r.reference_value = e.jaeger_slope;
  }
  r.error = std::abs(r.measured / r.reference_value - 1.0);
  r.error_definition = "|k_DEM / k_Jaeger - 1|";
  r.tolerance = 0.15;
  r.tolerance_source = "the uniaxial strength at 60 deg sits 14 % below Jaeger's (strength.jaeger_curve): the joints "
                       "fail progressively from the platen corners rather than at once, and confinement scales both "
                       "terms alike. One mesh's slope scatters by about 1.3 % (slopes_per_mesh), so the mean peaks of "
                       "five meshes are compared. The 90 deg row gives the DEM's intact envelope (phi, c), which has "
                       "no closed form";
  r.cost = fmt::format("{} confined runs at 1 mm, {} steps, {:.0f} s", 2 * confined_realizations + 2, c.steps,
                       c.seconds);
  return r;
}

// Two joint sets, the second (at 90 deg to the first) made a thousand times stronger than the first: the specimen
// must fail as the one-set specimen does (Jaeger's two planes reduce to one), at a dip where the first set slips
// (60 deg) and at one where the second set would sit at its own weakest angle if it were weak (30 deg).
CaseResult two_sets_reduce(const Context& ctx) {
  CaseResult r;
  r.checks = "the peak strength at 30 and 60 deg with a second joint set at 90 deg to the first whose bonds are "
             "1000 times stronger than the first set's";
  r.reference = "the one-set specimen (the default dip study at the same dips): Jaeger's two planes of weakness "
                "reduce to the weaker one (docs/theory.md, \"Two planes of weakness\")";
  r.unit = "Pa";
  const DipStudy& d = dip_study(ctx);
  Scene scene;
  scene.joint_set2.enabled = true;
  scene.joint_set2.follows_set1 = true;
  scene.joint_set2.dip_deg = 90.0;
  scene.joint_set2.spacing = 0.02;
  scene.joint2.tensile_strength = 1e3 * scene.joint.tensile_strength;
  scene.joint2.cohesion = 1e3 * scene.joint.cohesion;
  study::StudySpec spec = study::dip_study(scene, "verify_two_sets");
  spec.dips = {30, 60};
  const std::filesystem::path out = ctx.out / "two_sets";
  std::filesystem::create_directories(out);
  if (ctx.log) ctx.log("verify: running two joint sets, the second very strong, at 30 and 60 deg into " + out.string());
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = study::run_cases(study::expand(spec), out, study::SweepOptions{});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  long steps = 0;
  r.error = 0;
  for (const auto& c : results) {
    steps += c.summary["steps"].get<long>();
    const double p = c.summary["peak_stress_pa"].get<double>();
    for (const auto& one : d.results)
      if (one.c.beta == c.c.beta) {
        const double q = one.summary["peak_stress_pa"].get<double>();
        r.table.push_back({{"beta_deg", c.c.beta}, {"two_sets_pa", p}, {"one_set_pa", q}, {"difference", p / q - 1.0},
                           {"failure_mode_two_sets", c.summary["failure_mode"]},
                           {"failure_mode_one_set", one.summary["failure_mode"]}});
        const double scaled = std::abs(p / q - 1.0) / (c.c.beta == 60.0 ? 0.05 : 0.20);
        if (scaled >= r.error) r.error = scaled, r.measured = p, r.reference_value = q;
      }
  }
  r.error_definition = "max over the two dips of |sigma_two_sets / sigma_one_set - 1| / tol(beta), tol = 5 % at 60 "
                       "deg and 20 % at 30 deg (measured/reference: the peaks at the dip of the largest)";
  r.tolerance = 1.0;
  r.tolerance_source = "two different meshes (the second set's lines move the mesh): single meshes of one resolution "
                       "scatter with a standard deviation of 1.3 % at 60 deg and 5.3 % at 30 deg (five meshes, "
                       "docs/studies.md, \"Realizations\"), so two of them differ by 1.8 % and 7.5 % (one sd); "
                       "tol is about 2.7 of those. A second set as weak as the first would take the 30 deg strength "
                       "down by about 30 % (Jaeger: 31 against 45 MPa)";
  r.cost = fmt::format("2 UCS runs at 1 mm, {} steps, {:.0f} s (plus the default study's)", steps, seconds);
  return r;
}

}  // namespace

study::StudySpec confined_spec(const Scene& scene, const std::string& name) {
  study::StudySpec spec = study::dip_study(scene, name);
  spec.test = "triaxial";
  study::Axis axis;
  axis.name = "sigma3_mpa";
  axis.labels = {"0", "10"};
  axis.values = {{"loading.confining_pressure", {"0", "10e6"}}};
  spec.axes.push_back(axis);
  return spec;
}

std::vector<CaseSpec> strength_cases() {
  return {make_case("strength.min_angle", false, min_angle), make_case("strength.jaeger_curve", false, jaeger_curve),
          make_case("strength.triaxial_slope", false, triaxial_slope),
          make_case("strength.two_sets_reduce", false, two_sets_reduce)};
}

}  // namespace rbdem::verify
