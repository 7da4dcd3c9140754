// The central-difference integrator's order against the SUNDIALS ARKODE reference (compare/reference_integrator.hpp):
// the undamped bonded-block equations of motion of a small jointed specimen, integrated by ARKODE at rtol 1e-12
// and by the engine's own step() at four time steps.
#include <cmath>

#include <fmt/format.h>

#include "compare/reference_integrator.hpp"
#include "compare/verify/verify.hpp"

namespace rbdem::verify {

namespace {

CaseResult cd_order(const Context&) {
  CaseResult r;
  r.checks = "the order of the engine's central difference in dt (positions, undamped, bonded, jointed specimen)";
  r.reference = "SUNDIALS ARKODE ERKStep order 8 at rtol 1e-12 on the engine's own forces "
                "(docs/reference_integrator.md)";
  r.unit = "-";
  const ReferenceSpecimen sp;
  const ReferenceProblem p = make_reference_problem(sp);
  const auto sim = p.make_simulation();
  Engine<2>& e = sim->engine();
  const double t_end = 50.0 * p.stability_limit;
  const IntegrationResult ref =
      integrate_explicit(e, p.y0, t_end, Tolerances::scaled(1e-12, sp.strain * sp.height, sp.velocity, sp.mesh_size));
  const long n0 = long(std::ceil(t_end / (0.125 * p.stability_limit)));
  std::vector<double> dts, errors;
  for (int k = 0; k < 4; ++k) {
    const long n = n0 << k;
    const double dt = t_end / double(n);
    const IntegrationResult cd = central_difference(e, p.y0, dt, n);
    const StateError err = state_error(e, cd.state, ref.state, p.y0);
    dts.push_back(dt), errors.push_back(err.position);
    r.table.push_back({{"dt_over_limit", dt / p.stability_limit}, {"position_error", err.position},
                       {"velocity_error", err.velocity}, {"steps", n}, {"seconds", cd.stats.wall_seconds}});
  }
  r.table.push_back({{"arkode_steps", ref.stats.steps}, {"arkode_rhs_evals", ref.stats.rhs_evals},
                     {"arkode_seconds", ref.stats.wall_seconds}});
  std::vector<double> lx, ly;
  for (std::size_t k = 0; k < dts.size(); ++k) lx.push_back(std::log(dts[k])), ly.push_back(std::log(errors[k]));
  r.measured = least_squares_slope(lx, ly);
  r.reference_value = 2.0;
  r.error = std::abs(r.measured - 2.0);
  r.error_definition =
      "|fitted slope of log(position error) over log(dt) - 2|, dt = 1/8 to 1/64 of the stability limit";
  r.tolerance = 0.2;
  r.tolerance_source = "second order of central difference; 0.2 allows the next term over a factor 8 in dt "
                       "(the issue's 1.8-2.2)";
  r.cost = fmt::format("{} blocks, {} to {} steps, ARKODE {} steps", p.engine().model().num_blocks(), n0, n0 << 3,
                       ref.stats.steps);
  return r;
}

}  // namespace

std::vector<CaseSpec> reference_cases() { return {make_case("dem.central_difference_order", true, cd_order)}; }

}  // namespace rbdem::verify
