// Brazilian disc cases: the stress at the centre of a disc under two opposite diametral forces, below failure, from
// the DEM (static solve), from the deal.II disc model on the same mesh (continuum/fe_disc.hpp) and from the closed
// forms (theory/disc.hpp; docs/theory.md, section 9): Hondros for the isotropic disc, Claesson & Bohloli's
// approximation for the layered one.
//
// The DEM's stress is a volume average (Love-Weber over the blocks whose centroid lies within r_avg of the centre,
// dem/measure.hpp), so it is compared with the mean of the same field over the same circle: Hondros's exact mean for
// the isotropic disc, the FE's mean over the same radius for the layered one. The closed form of the layered disc
// is a point value at the centre; the FE gives both, so the DEM's centre value is its mean times the FE's ratio of
// centre to mean (a correction of about 4 % at r_avg = R / 5, the curvature of the field).
#include <chrono>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "compare/gate/dem_constants.hpp"
#include "compare/verify/verify.hpp"
#include "dem/simulation_impl.hpp"
#include "dem/measure.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"
#include "theory/disc.hpp"
#include "theory/elasticity.hpp"
#if RBDEM_HAVE_CONTINUUM
#include "continuum/fe_disc.hpp"
#endif

namespace rbdem::verify {

namespace {

// The paper scene as a full disc (point loads need the nodes at the top and bottom, no flattened ends).
Scene disc_scene(bool joints, double dip_deg, double mesh_size) {
  Scene s;
  s.specimen.shape = "disc";
  s.specimen.contact_arc_deg = 0.0;
  s.joint_set.enabled = joints;
  s.joint_set.dip_deg = dip_deg;
  s.mesh.size = mesh_size;
  return s;
}

// The DEM disc under +-P at its top and bottom nodes, the block nearest the centre anchored against the rigid
// modes (the load has no resultant), solved statically: the mean stress over radius `radius`.
struct DemDisc {
  StressTensor mean;
  double cx = 0, cy = 0, R = 0;
  std::size_t blocks = 0, bonds = 0, open = 0;
};

DemDisc dem_disc(const Scene& s, const TriMesh& mesh, double P, double radius_fraction) {
  SimulationImpl<2> sim(s, mesh, {}, [](EngineOptions& o) { o.contacts = false, o.threads = 1; });
  const Topology<2>& topo = sim.topology();
  DemDisc d;
  d.cx = 0.5 * (topo.xmin + topo.xmax), d.cy = 0.5 * (topo.ymin + topo.ymax), d.R = 0.5 * topo.width();
  int anchor = 0;
  double best = 1e300;
  for (std::size_t b = 0; b < topo.blocks.size(); ++b) {
    const double r = std::hypot(topo.blocks.cx[b] - d.cx, topo.blocks.cy[b] - d.cy);
    if (r < best) best = r, anchor = static_cast<int>(b);
  }
  StaticOptions so;
  so.platens = false;
  so.anchors = {anchor};
  so.load = diametral_load(sim.engine(), mesh, P);
  const StaticResult st = sim.solve_static(so);
  sim.apply_static({}, st, 1.0, 0.0);
  d.mean = average_stress(sim, Region::circle({d.cx, d.cy}, radius_fraction * d.R));
  d.blocks = topo.blocks.size(), d.bonds = topo.bonds.size(), d.open = st.open_bonds;
  return d;
}

// The load giving a centre tension of 1 MPa in the isotropic disc: 2 P / (pi D t) = 1 MPa.
double unit_load(const Scene& s) { return 1e6 * std::numbers::pi * s.specimen.diameter * s.specimen.thickness / 2.0; }

CaseResult disc_hondros(const Context&) {
  CaseResult r;
  r.checks = "the DEM's mean stress over the central circle r <= R/5 of an unjointed disc under diametral point "
             "loads, at two mesh sizes";
  r.reference = "Hondros's isotropic disc, averaged over the same circle (docs/theory.md, section 9)";
  r.unit = "MPa";
  r.error_definition = "max over the mesh sizes of |sigma_xx / ref - 1| and |sigma_yy / ref - 1| (xx: the tension "
                       "across the loaded diameter, 2P/(pi D t) at the centre; yy: -3 times that)";
  const double frac = 0.2;
  double worst = 0;
  std::size_t blocks = 0;
  for (double h : {0.002, 0.001}) {
    const Scene s = disc_scene(false, 0, h);
    const TriMesh mesh = make_mesh(s);
    const double P = unit_load(s);
    const DemDisc d = dem_disc(s, mesh, P, frac);
    const DemDisc pulled = dem_disc(s, mesh, -P, frac);  // the same forces reversed: a linear model flips sign
    const theory::DiscStress ref =
        theory::hondros_mean_stress(P, s.specimen.diameter, s.specimen.thickness, frac * d.R);
    const double exx = d.mean.xx() / ref.xx - 1, eyy = d.mean.yy() / ref.yy - 1;
    worst = std::max({worst, std::abs(exx), std::abs(eyy)});
    blocks = d.blocks;
    r.table.push_back({{"mesh_size_m", h}, {"blocks_averaged", int(d.mean.blocks)}, {"sxx_pa", d.mean.xx()},
                       {"sxx_ref_pa", ref.xx}, {"syy_pa", d.mean.yy()}, {"syy_ref_pa", ref.yy}, {"sxy_pa", d.mean.xy()},
                       {"error_xx", exx}, {"error_yy", eyy},
                       {"pulled_sxx_pa", -pulled.mean.xx()}, {"pulled_syy_pa", -pulled.mean.yy()},
                       {"pulled_error_xx", -pulled.mean.xx() / ref.xx - 1},
                       {"pulled_error_yy", -pulled.mean.yy() / ref.yy - 1}});
    r.measured = d.mean.xx() / 1e6, r.reference_value = ref.xx / 1e6;  // the finest mesh's sigma_xx
  }
  r.error = worst;
  r.tolerance = 0.05;
  r.tolerance_source = "the agreement asked of the Brazilian protocol's stress (5 %). The DEM is not linear: a bond's "
                       "linear part carries compression only, so its tension stiffness is half its compression "
                       "stiffness; the rows 'pulled' reverse the forces (a linear model would give the same numbers "
                       "with the sign flipped) and measure that asymmetry";
  r.cost = fmt::format("2 static disc solves (2 mm and 1 mm, {} blocks)", blocks);
  return r;
}

#if RBDEM_HAVE_CONTINUUM

// The layered disc at layer angles 0, 45 and 90 deg (dips 90, 45, 0): DEM, FE with the DEM's own constants, and
// Claesson & Bohloli with the same constants. `soft`: joints ten times softer than the paper's at 2.5 mm spacing,
// a strongly anisotropic disc (E/E' about 2) where the closed form's approximation is no longer exact.
CaseResult layered_disc(const Context&, bool soft) {
  CaseResult r;
  r.checks = soft ? "the centre tension of a strongly layered disc (joints at 2.5 mm, joint modulus 5 GPa) at layer "
                    "angles 0, 45 and 90 deg: DEM, FE on the same mesh and the closed form"
                  : "the centre tension of the paper's layered disc (joints at 10 mm) at layer angles 0, 45 and 90 "
                    "deg: DEM, FE on the same mesh and the closed form";
  r.reference = "Claesson & Bohloli's approximate centre tension of a transversely isotropic disc and the deal.II "
                "disc, both with the DEM's five constants fitted from virtual tests at dips 0, 45, 90 "
                "(docs/theory.md, section 9)";
  r.unit = "-";
  Scene base;
  if (soft) {
    base.joint.effective_modulus = 5e9;
    base.joint_set.spacing = 0.0025;
  }
  const theory::Plane plane = theory::plane_from_string(base.specimen.model);

  // The DEM's constants: static virtual tests on the rectangular specimen.
  std::vector<compare::VirtualTest> tests;
  for (double dip : {0.0, 45.0, 90.0}) {
    Scene s = compare::elastic_test_scene(base);
    s.joint_set.dip_deg = dip;
    const TriMesh mesh = make_mesh(s);
    tests.push_back(compare::virtual_test(build_topology(mesh, s.specimen.thickness, s.rock.density), s, dip, 0.2));
  }
  const compare::ComplianceFit fit = compare::fit_compliance(tests, plane);
  const theory::TIConstants c = fit.constants;

  const double frac = 0.2;  // as the isotropic case; the table of docs/verification.md shows 0.1 to 0.5
  double worst = 0, fe_seconds = 0;
  std::size_t blocks = 0, dofs = 0;
  for (double angle : {0.0, 45.0, 90.0}) {
    const double dip = 90.0 - angle;
    Scene s = base;
    s.specimen.shape = "disc";
    s.specimen.contact_arc_deg = 0.0;
    s.joint_set.dip_deg = dip;
    const TriMesh mesh = make_mesh(s);
    const double P = unit_load(s), s0 = 1e6;
    const DemDisc d = dem_disc(s, mesh, P, frac);
    const DemDisc pulled = dem_disc(s, mesh, -P, frac);
    continuum::DiscOptions fo;
    fo.average_radius = frac * d.R;
    const continuum::DiscResult fe = continuum::solve_disc(mesh, c, dip, plane, P, s.specimen.thickness, fo);
    const double dem_mean = theory::principal_tension({d.mean.xx(), d.mean.yy(), d.mean.xy()});
    const double pulled_mean = theory::principal_tension({-pulled.mean.xx(), -pulled.mean.yy(), -pulled.mean.xy()});
    const double fe_mean = theory::principal_tension(fe.centre_mean);
    const double fe_centre = theory::principal_tension(fe.centre_fit);
    const double cb = theory::claesson_bohloli_centre_tension(c, plane, dip, P, s.specimen.diameter,
                                                              s.specimen.thickness);
    const double dem_centre = dem_mean * fe_centre / fe_mean;
    const double e_dem_fe = dem_mean / fe_mean - 1, e_fe_cb = fe_centre / cb - 1, e_dem_cb = dem_centre / cb - 1;
    worst = std::max({worst, std::abs(e_dem_fe), std::abs(e_fe_cb), std::abs(e_dem_cb)});
    blocks = d.blocks, dofs = fe.dofs, fe_seconds += fe.seconds;
    r.table.push_back({{"layer_angle_deg", angle}, {"dip_deg", dip}, {"dem_mean_factor", dem_mean / s0},
                       {"fe_mean_factor", fe_mean / s0}, {"fe_centre_factor", fe_centre / s0},
                       {"dem_centre_factor", dem_centre / s0}, {"claesson_bohloli_factor", cb / s0},
                       {"dem_vs_fe", e_dem_fe}, {"dem_pulled_mean_factor", pulled_mean / s0},
                       {"dem_pulled_vs_fe", pulled_mean / fe_mean - 1}, {"fe_vs_closed_form", e_fe_cb}, {"dem_vs_closed_form", e_dem_cb}});
    if (angle == 0.0) r.measured = dem_centre / s0, r.reference_value = cb / s0;
  }
  r.table.push_back({{"E_pa", c.E}, {"E_prime_pa", c.E_prime}, {"nu", c.nu}, {"nu_prime", c.nu_prime},
                     {"G_prime_pa", c.G_prime}, {"fit_residual", fit.residual}});
  r.error = worst;
  r.error_definition = "max over the three angles of |DEM mean / FE mean - 1|, |FE centre / closed form - 1| and "
                       "|DEM centre / closed form - 1| (measured/reference: the factor sigma_t / (2P/(pi D t)) at "
                       "layer angle 0)";
  r.tolerance = soft ? std::nan("") : 0.05;
  r.tolerance_source = soft ? "informational: the DEM's E/E' here is about 6.7, beyond the closed form's range "
                              "(its error is 14-21 % at E/E' = 4 against the converged FE, tests/test_disc.cpp), "
                              "and 2.5 mm joints in 1 mm blocks are barely a continuum; the table shows how far "
                              "each of the three is from the others"
                            : "the agreement asked of the Brazilian protocol (5 %); the closed form's own error "
                              "for these constants is 0.2 % (tests/test_disc.cpp, FE converged). The FE and the "
                              "closed form are linear, the DEM is not (brazilian.hondros): the 'pulled' columns "
                              "reverse the forces";
  r.cost = fmt::format("3 virtual tests, 3 static disc solves ({} blocks), 3 FE discs ({} DoFs, {:.1f} s)", blocks,
                       dofs, fe_seconds);
  return r;
}

CaseResult paper_disc(const Context& ctx) { return layered_disc(ctx, false); }
CaseResult soft_disc(const Context& ctx) { return layered_disc(ctx, true); }

#endif

}  // namespace

std::vector<CaseSpec> disc_cases() {
  std::vector<CaseSpec> cases{make_case("brazilian.hondros", true, disc_hondros)};
#if RBDEM_HAVE_CONTINUUM
  cases.push_back(make_case("brazilian.layered_disc", false, paper_disc));
  cases.push_back(make_case("brazilian.strongly_layered_disc", false, soft_disc));
#endif
  return cases;
}

}  // namespace rbdem::verify
