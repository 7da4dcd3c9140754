// The Brazilian disc measurements of compare/verify/disc_measures.hpp: the DEM disc solved statically (with its
// linear parts held closed or as they run), the deal.II disc with the linear DEM's constants and the closed form.
#include "compare/verify/disc_measures.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "compare/gate/dem_constants.hpp"
#include "dem/simulation_impl.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"
#include "theory/disc.hpp"
#if RBDEM_HAVE_CONTINUUM
#include "continuum/fe_disc.hpp"
#endif

namespace rbdem::verify {

Scene disc_scene(const Scene& base, bool joints, double dip_deg) {
  Scene s = base;
  s.specimen.shape = "disc";
  s.specimen.contact_arc_deg = 0.0;
  s.joint_set.enabled = joints;
  s.joint_set.dip_deg = dip_deg;
  return s;
}

double unit_disc_load(const Scene& s) {
  return 1e6 * std::numbers::pi * s.specimen.diameter * s.specimen.thickness / 2.0;
}

DemDisc dem_disc(const Scene& s, const TriMesh& mesh, double P, double radius_fraction, bool linear_parts_closed) {
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
  so.linear_parts_always_closed = linear_parts_closed;
  const StaticResult st = sim.solve_static(so);
  const Region centre = Region::circle({d.cx, d.cy}, radius_fraction * d.R);
  if (linear_parts_closed) {
    d.mean = static_stress(sim, st, centre);  // the linear model's own forces: closed linear parts pull too
  } else {
    sim.apply_static({}, st, 1.0, 0.0);  // the laws as they run, on the solved state
    d.mean = average_stress(sim, centre);
  }
  d.blocks = topo.blocks.size(), d.bonds = topo.bonds.size(), d.open = st.open_bonds;
  return d;
}

#if RBDEM_HAVE_CONTINUUM

namespace {

// The principal tension of the DEM's mean stress; `sign` -1 flips a pulled disc back.
double tension(const StressTensor& m, double sign = 1.0) {
  return theory::principal_tension({sign * m.xx(), sign * m.yy(), sign * m.xy()});
}

// The linear DEM's five constants: static virtual tests on the rectangular specimen at dips 0, 45, 90 with every
// linear part held closed (as the disc it is compared with).
compare::ComplianceFit linear_constants(const Scene& base, theory::Plane plane) {
  std::vector<compare::VirtualTest> tests;
  for (double dip : {0.0, 45.0, 90.0}) {
    Scene s = compare::elastic_test_scene(base);
    s.joint_set.dip_deg = dip;
    const TriMesh mesh = make_mesh(s);
    tests.push_back(compare::virtual_test(build_topology(mesh, s.specimen.thickness, s.rock.density), s, dip, 0.2,
                                          nullptr, true));
  }
  return compare::fit_compliance(tests, plane);
}

}  // namespace

LayeredDisc layered_disc(const Scene& base, const std::vector<double>& layer_angles_deg, double radius_fraction) {
  const theory::Plane plane = theory::plane_from_string(base.specimen.model);
  const compare::ComplianceFit fit = linear_constants(base, plane);
  LayeredDisc out;
  out.constants = fit.constants, out.fit_residual = fit.residual, out.mesh_size = base.mesh.size;
  for (double angle : layer_angles_deg) {
    DiscAngle a;
    a.layer_angle_deg = angle, a.dip_deg = 90.0 - angle;
    const Scene s = disc_scene(base, base.joint_set.enabled, a.dip_deg);
    const TriMesh mesh = make_mesh(s);
    const double P = unit_disc_load(s);
    const DemDisc closed = dem_disc(s, mesh, P, radius_fraction, true);
    const DemDisc pushed = dem_disc(s, mesh, P, radius_fraction, false);
    const DemDisc pulled = dem_disc(s, mesh, -P, radius_fraction, false);
    a.dem_mean = tension(closed.mean), a.dem_as_run_mean = tension(pushed.mean);
    a.dem_pulled_mean = tension(pulled.mean, -1.0);
    a.open_as_run = pushed.open, a.open_pulled = pulled.open;
    continuum::DiscOptions fo;
    fo.average_radius = radius_fraction * closed.R;
    const continuum::DiscResult fe =
        continuum::solve_disc(mesh, out.constants, a.dip_deg, plane, P, s.specimen.thickness, fo);
    a.fe_mean = theory::principal_tension(fe.centre_mean);
    a.fe_centre = theory::principal_tension(fe.centre_fit);
    a.closed_form = theory::claesson_bohloli_centre_tension(out.constants, plane, a.dip_deg, P,
                                                            s.specimen.diameter, s.specimen.thickness);
    out.blocks = closed.blocks, out.bonds = closed.bonds, out.fe_dofs = fe.dofs, out.fe_seconds += fe.seconds;
    out.angles.push_back(a);
  }
  return out;
}

#else

LayeredDisc layered_disc(const Scene&, const std::vector<double>&, double) {
  throw std::runtime_error("layered_disc: the FE disc needs the deal.II build (RBDEM_WITH_DEALII)");
}

#endif

double like_for_like_error(const LayeredDisc& d) {
  double worst = 0;
  for (const DiscAngle& a : d.angles)
    worst = std::max({worst, std::abs(a.dem_mean / a.fe_mean - 1), std::abs(a.fe_centre / a.closed_form - 1),
                      std::abs(a.dem_centre() / a.closed_form - 1)});
  return worst;
}

}  // namespace rbdem::verify
