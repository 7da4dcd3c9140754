// Explicit central difference against implicit ARKStep (SDIRK order 4, banded Newton, difference-quotient Jacobian)
// on the small jointed specimen of compare/reference_integrator.hpp, for a normal case (joints as stiff as rock) and
// a stiff one (joints 1e4 times softer than rock): wall time and error against the ARKODE explicit reference, and for
// each implicit run the cheapest central-difference run that is at least as accurate. docs/reference_integrator.md
// has the tables this prints.
//
// Usage:
//   bench_reference [--case normal|stiff|all] [--periods N] [--ref-rtol R] [--implicit-rtol R ...]
// Sample runs:
//   bench_reference                               # both cases, the defaults below (a few minutes)
//   bench_reference --case normal --implicit-rtol 1e-3 1e-5
//   bench_reference --case stiff --periods 2000 --ref-rtol 1e-10 --implicit-rtol 1e-2
// --periods is the end time in units of the central difference's stability limit (stability_limit()).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "compare/reference_integrator.hpp"

namespace {

using namespace rbdem;

struct CaseSetup {
  std::string name;
  ReferenceSpecimen specimen;
  double periods;   // end time / stability limit
  double ref_rtol;  // tolerance of the reference
};

void run_case(const CaseSetup& c, const std::vector<double>& implicit_rtols) {
  const ReferenceSpecimen& sp = c.specimen;
  const ReferenceProblem p = make_reference_problem(sp);
  const auto sim = p.make_simulation();
  rbdem::Engine<2>& e = sim->engine();
  const double t_end = c.periods * p.stability_limit;
  auto tol = [&](double rtol) { return Tolerances::scaled(rtol, sp.strain * sp.height, sp.velocity, sp.mesh_size); };
  fmt::print("\n## case {}: E_rock / E_joint = {:g}, initial field {}, {} blocks, {} bonds, stability limit {:.4g} s, "
             "t_end = {:g} x limit = {:.4g} s\n",
             c.name, sp.joint_contrast, sp.field == InitialField::smooth ? "smooth" : "layer_rigid",
             p.engine().model().num_blocks(), p.engine().model().num_bonds(), p.stability_limit, c.periods, t_end);

  const IntegrationResult ref = integrate_explicit(e, p.y0, t_end, tol(c.ref_rtol));
  const IntegrationResult check = integrate_explicit(e, p.y0, t_end, tol(100.0 * c.ref_rtol));
  const StateError ref_err = state_error(e, check.state, ref.state, p.y0);
  fmt::print("reference: ERKStep Fehlberg 13-stage order 8, rtol {:.0e}: {} steps ({} attempts), {} force evaluations, "
             "{:.3f} s wall, {:.3f} s CPU; the same at rtol {:.0e} differs by {:.2e} (positions), {:.2e} (velocities)\n",
             c.ref_rtol, ref.stats.steps, ref.stats.attempts, ref.stats.rhs_evals, ref.stats.wall_seconds, ref.stats.cpu_seconds,
             100.0 * c.ref_rtol, ref_err.position, ref_err.velocity);

  struct Run {
    double rtol;
    IntegrationResult result;
    StateError err;
  };
  std::vector<Run> implicit;
  double target = 1e300;  // the smallest implicit error: central difference is refined until it is as accurate
  for (double rtol : implicit_rtols) {
    IntegrationResult r = integrate_implicit(e, p.y0, t_end, tol(rtol));
    const StateError err = state_error(e, r.state, ref.state, p.y0);
    target = std::min(target, err.position);
    implicit.push_back({rtol, std::move(r), err});
  }

  fmt::print("\n| central difference dt / limit | steps | position error | velocity error | wall s | CPU s |\n"
             "|---|---|---|---|---|---|\n");
  struct Row {
    double err, seconds;
  };
  std::vector<Row> cd;
  for (double frac = 0.8; frac > 1e-4; frac *= 0.5) {
    const long n = long(std::ceil(t_end / (frac * p.stability_limit)));
    const IntegrationResult r = central_difference(e, p.y0, t_end / double(n), n);
    const StateError err = state_error(e, r.state, ref.state, p.y0);
    cd.push_back({err.position, r.stats.cpu_seconds});
    fmt::print("| {:.4f} | {} | {:.3e} | {:.3e} | {:.4f} | {:.4f} |\n", t_end / double(n) / p.stability_limit, n,
               err.position, err.velocity, r.stats.wall_seconds, r.stats.cpu_seconds);
    if (err.position < target && cd.size() >= 4) break;
  }

  fmt::print("\n| implicit rtol | steps | Newton its | Jacobians | force evals | position error | velocity error | wall s "
             "| CPU s | cheapest central difference at least as accurate: CPU s | faster |\n"
             "|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Run& run : implicit) {
    const IntegrationStats& st = run.result.stats;
    double best = -1;
    for (const Row& row : cd)
      if (row.err <= run.err.position && (best < 0 || row.seconds < best)) best = row.seconds;
    const std::string cd_time = best < 0 ? "none in the table" : fmt::format("{:.4f}", best);
    const std::string faster = best < 0 ? "?" : (st.cpu_seconds < best ? "implicit" : "explicit");
    fmt::print("| {:.0e} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3f} | {:.3f} | {} | {} |\n", run.rtol, st.steps,
               st.newton_iters, st.jacobian_evals, st.rhs_evals, run.err.position, run.err.velocity, st.wall_seconds,
               st.cpu_seconds, cd_time, faster);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Explicit central difference vs implicit ARKStep against the ARKODE reference"};
  std::string which = "all";
  double periods = 0, ref_rtol = 0;
  std::vector<double> implicit_rtols{1e-2, 1e-3, 1e-4, 1e-5};
  app.add_option("--case", which, "normal, stiff or all")->check(CLI::IsMember({"normal", "stiff", "all"}));
  app.add_option("--periods", periods, "end time in stability limits (default: normal 100, stiff 1000)");
  app.add_option("--ref-rtol", ref_rtol, "reference tolerance (default 1e-12)");
  app.add_option("--implicit-rtol", implicit_rtols, "tolerances of the implicit runs");
  CLI11_PARSE(app, argc, argv);

  CaseSetup normal{"normal", {}, 100.0, 1e-12};
  CaseSetup stiff{"stiff", {}, 1000.0, 1e-12};
  stiff.specimen.joint_contrast = 1e4;
  stiff.specimen.field = InitialField::layer_rigid;
  for (CaseSetup* c : {&normal, &stiff}) {
    if (which != "all" && which != c->name) continue;
    if (periods > 0) c->periods = periods;
    if (ref_rtol > 0) c->ref_rtol = ref_rtol;
    run_case(*c, implicit_rtols);
  }
  return 0;
}
