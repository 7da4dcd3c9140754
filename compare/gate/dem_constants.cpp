// DEM-measured elastic constants and Goodman's estimate. See dem_constants.hpp.
#include "compare/gate/dem_constants.hpp"

#include "dem/materials.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "dem/simulation_impl.hpp"

namespace rbdem::compare {

GaugeStrain gauge_strain(const Topology<2>& topo, const std::vector<double>& ux, const std::vector<double>& uy,
                         double end_fraction) {
  const auto& B = topo.blocks;
  const double lo = topo.ymin + end_fraction * topo.height(), hi = topo.ymax - end_fraction * topo.height();
  // Centred coordinates keep the 3 x 3 normal equations well conditioned.
  double mx = 0, my = 0, mux = 0, muy = 0;
  std::size_t n = 0;
  for (std::size_t b = 0; b < B.size(); ++b)
    if (B.cy[b] >= lo && B.cy[b] <= hi) mx += B.cx[b], my += B.cy[b], mux += ux[b], muy += uy[b], ++n;
  if (n < 3)
    throw std::invalid_argument(fmt::format("strain gauge: only {} blocks lie in the interior (end fraction {}): "
                                            "refine mesh.size",
                                            n, end_fraction));
  mx /= double(n), my /= double(n), mux /= double(n), muy /= double(n);
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rx = Eigen::Vector2d::Zero(), ry = Eigen::Vector2d::Zero();
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.cy[b] < lo || B.cy[b] > hi) continue;
    const Eigen::Vector2d p(B.cx[b] - mx, B.cy[b] - my);
    M += p * p.transpose();
    rx += p * (ux[b] - mux);
    ry += p * (uy[b] - muy);
  }
  const Eigen::Vector2d gx = M.ldlt().solve(rx), gy = M.ldlt().solve(ry);  // (du/dx, du/dy)
  GaugeStrain g;
  g.eps_xx = gx[0], g.eps_yy = gy[1], g.gamma_xy = gx[1] + gy[0];
  g.rotation = 0.5 * (gy[0] - gx[1]);
  g.blocks = n;
  double res2 = 0, fit2 = 0;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.cy[b] < lo || B.cy[b] > hi) continue;
    const double px = B.cx[b] - mx, py = B.cy[b] - my;
    const double fx = gx[0] * px + gx[1] * py, fy = gy[0] * px + gy[1] * py;
    res2 += std::pow(ux[b] - mux - fx, 2) + std::pow(uy[b] - muy - fy, 2);
    fit2 += fx * fx + fy * fy;
  }
  g.misfit = fit2 > 0 ? std::sqrt(res2 / fit2) : 0.0;
  return g;
}

Scene elastic_test_scene(const Scene& scene) {
  Scene s = scene;
  s.loading.platen_friction = 0.0;
  return s;
}

VirtualTest virtual_test(const Topology<2>& topo, const Scene& scene, double beta_deg, double end_fraction,
                         StaticResult* state, bool linear_parts_closed) {
  Scene s = elastic_test_scene(scene);
  s.numerics.threads = 1;  // the static solve does not use the run's threads; angles run in parallel instead
  SimulationImpl<2> impl(s, topo);
  Simulation& sim = impl;
  sim.add_platens({s.loading.platen_velocity, s.loading.platen_friction});
  StaticOptions so;
  so.platen_displacement = 1e-5 * topo.height();
  so.linear_parts_always_closed = linear_parts_closed;
  StaticResult r = sim.solve_static(so);
  VirtualTest t;
  t.beta_deg = beta_deg;
  t.platen_displacement = r.platen_displacement;
  t.stress = -0.5 * (r.top_force + r.bottom_force) / (topo.width() * topo.thickness);
  t.platen_modulus = r.apparent_modulus;
  t.gauge = gauge_strain(topo, r.component(0), r.component(1), end_fraction);
  t.gauge_modulus = t.stress / t.gauge.eps_yy;
  t.S12 = t.gauge.eps_xx / t.stress;
  t.S22 = t.gauge.eps_yy / t.stress;
  t.S26 = t.gauge.gamma_xy / t.stress;
  t.blocks = topo.blocks.size();
  t.bonds = topo.bonds.size();
  t.joint_bonds = topo.count(BondKind::joint);
  t.open_bonds = r.open_bonds;
  for (std::size_t b = 0; b < r.linear_state.size(); ++b)
    t.open_joint_bonds += r.linear_state[b] == StaticResult::open && topo.bonds.kind[b] == BondKind::joint ? 1 : 0;
  t.sliding_bonds = r.sliding_bonds;
  t.dofs = r.dofs;
  t.active_set_iterations = r.active_set_iterations;
  t.solve_seconds = r.seconds;
  if (state) *state = std::move(r);
  return t;
}

ComplianceFit fit_compliance(const std::vector<VirtualTest>& tests, theory::Plane plane) {
  if (tests.size() < 3)
    throw std::invalid_argument("compliance fit: needs virtual tests at three or more angles (e.g. 0, 45, 90 deg)");
  const long m = long(3 * tests.size());
  Eigen::MatrixXd A(m, 4);
  Eigen::VectorXd b(m);
  for (std::size_t k = 0; k < tests.size(); ++k) {
    // Each test relative to its own |S22|: the stiff directions weigh as much as the soft ones.
    const double w = std::abs(tests[k].S22) > 0 ? 1.0 / std::abs(tests[k].S22) : 1.0;
    // The rotated compliance is linear in (a11, a22, a12, a66): its columns are the images of the unit vectors.
    for (int c = 0; c < 4; ++c) {
      theory::ReducedCompliance unit;
      (c == 0 ? unit.a11 : c == 1 ? unit.a22 : c == 2 ? unit.a12 : unit.a66) = 1.0;
      const auto S = theory::rotated_compliance(unit, tests[k].beta_deg);
      A(long(3 * k), c) = w * S[0][1];
      A(long(3 * k + 1), c) = w * S[1][1];
      A(long(3 * k + 2), c) = w * S[1][2];
    }
    b[long(3 * k)] = w * tests[k].S12;
    b[long(3 * k + 1)] = w * tests[k].S22;
    b[long(3 * k + 2)] = w * tests[k].S26;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 4)
    throw std::invalid_argument(
        "compliance fit: the test angles do not determine the four compliances (use 0, 45, 90)");
  const Eigen::Vector4d x = qr.solve(b);
  const Eigen::VectorXd res = A * x - b;
  ComplianceFit f;
  f.a = {x[0], x[1], x[2], x[3]};
  f.constants = theory::constants_from_compliance(f.a, plane);
  f.residual = std::sqrt(res.squaredNorm() / double(m));
  f.max_residual = res.cwiseAbs().maxCoeff();
  f.tests = tests.size();
  // Each unknown scaled by its own size: the condition number then bounds relative errors of the constants.
  Eigen::Vector4d scale(std::abs(x[0]), std::abs(x[1]), std::sqrt(std::abs(x[0] * x[1])), std::abs(x[3]));
  for (int c = 0; c < 4; ++c)
    if (!(scale[c] > 0)) scale[c] = 1.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A * scale.asDiagonal());
  const auto& sv = svd.singularValues();
  f.condition = sv[sv.size() - 1] > 0 ? sv[0] / sv[sv.size() - 1] : std::numeric_limits<double>::infinity();
  f.admissible = f.constants.admissible();
  return f;
}

theory::TIConstants isotropic_constants(const VirtualTest& test, theory::Plane plane) {
  const theory::ReducedCompliance a{test.S22, test.S22, test.S12, 2.0 * (test.S22 - test.S12)};
  return theory::constants_from_compliance(a, plane);
}

void JointBondStats::add(const Topology<2>& topo) {
  for (std::size_t b = 0; b < topo.bonds.size(); ++b)
    if (topo.bonds.kind[b] == BondKind::joint) {
      sum_length += topo.bonds.length[b];
      sum_length_d += topo.bonds.length[b] * topo.bonds.d[b];
      ++count;
    }
}

GoodmanEstimate goodman_estimate(const Scene& scene, const theory::TIConstants& intact, double d_mean) {
  GoodmanEstimate g;
  g.E_r = intact.E, g.nu_r = intact.nu;
  g.spacing = scene.joint_set.spacing;
  g.d_mean = d_mean;
  const double inf = std::numeric_limits<double>::infinity();
  // Extra compliance per area of a joint bond over the rock bond it replaces (2 E*/d per area in compression).
  const JointCompliance c = joint_compliance(scene);
  const double cn = d_mean * c.c_n, cs = d_mean * c.c_s;
  const bool joints = scene.joint_set.enabled && d_mean > 0;
  g.k_n = joints && cn != 0.0 ? 1.0 / cn : inf;
  g.k_s = joints && cs != 0.0 ? 1.0 / cs : inf;
  g.constants = theory::goodman(g.E_r, g.nu_r, g.k_n, g.k_s, g.spacing);
  return g;
}

}  // namespace rbdem::compare

namespace rbdem::compare {

JointCompliance joint_compliance(const Scene& scene) { return joint_compliance(scene, scene.joint); }

JointCompliance joint_compliance(const Scene& scene, const MaterialParams& j) {
  return joint_compliance(j, scene.rock, scene.rock, 1.0);
}

JointCompliance joint_compliance(const MaterialParams& j, const MaterialParams& r1, const MaterialParams& r2,
                                 double f1) {
  // The compliance per area and per unit d of the rock bond a joint bond replaces: one rock's, or the two half
  // chains from each centroid to the edge, each of its own rock.
  const bool one = &r1 == &r2;
  const double rn = one ? 1.0 / (2.0 * r1.effective_modulus)
                        : f1 / (2.0 * r1.effective_modulus) + (1.0 - f1) / (2.0 * r2.effective_modulus);
  const double rs = one ? r1.stiffness_ratio / (2.0 * r1.effective_modulus)
                        : f1 * r1.stiffness_ratio / (2.0 * r1.effective_modulus) +
                              (1.0 - f1) * r2.stiffness_ratio / (2.0 * r2.effective_modulus);
  return {1.0 / (2.0 * j.effective_modulus) - rn, j.stiffness_ratio / (2.0 * j.effective_modulus) - rs,
          1.0 / j.effective_modulus - rn, j.stiffness_ratio / j.effective_modulus - rs};
}

void JointInterfaces::merge(const JointInterfaces& o) {
  edges.insert(edges.end(), o.edges.begin(), o.edges.end());
  glued += o.glued, stiffened += o.stiffened, sum_length += o.sum_length;
  sum_length_compliance_n += o.sum_length_compliance_n, sum_length_compliance_s += o.sum_length_compliance_s;
}

double JointInterfaces::mean_k_n() const {
  return sum_length_compliance_n > 0 ? sum_length / sum_length_compliance_n : std::numeric_limits<double>::infinity();
}

double JointInterfaces::mean_k_s() const {
  return sum_length_compliance_s > 0 ? sum_length / sum_length_compliance_s : std::numeric_limits<double>::infinity();
}

JointInterfaces joint_interfaces(const Topology<2>& topo, const Scene& scene, double intact_E) {
  const MaterialMap materials = assign_materials(topo, scene);
  const double inf = std::numeric_limits<double>::infinity();
  JointInterfaces out;
  const auto& B = topo.bonds;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.kind[b] != BondKind::joint) continue;
    // Each side's rock: the fraction f_i = n . (m - c_i) / d of the centroid distance lies in block i.
    const auto i = std::size_t(B.i[b]), j = std::size_t(B.j[b]);
    const double f_i = (B.nx[b] * (B.mx[b] - topo.blocks.cx[i]) + B.ny[b] * (B.my[b] - topo.blocks.cy[i])) / B.d[b];
    const JointCompliance c = joint_compliance(material_params(scene, materials.bond[b]),
                                               material_params(scene, materials.block[i]),
                                               material_params(scene, materials.block[j]), f_i);
    JointInterface e;
    e.node_a = B.node_a[b], e.node_b = B.node_b[b], e.d = B.d[b], e.length = B.length[b];
    const bool rigid_n = !(c.c_n > 0), rigid_s = !(c.c_s > 0);
    const double penalty = 1e4 * intact_E / e.d;
    e.glued = rigid_n && rigid_s;
    e.k_n = e.glued ? inf : rigid_n ? penalty : 1.0 / (e.d * c.c_n);
    e.k_s = e.glued ? inf : rigid_s ? penalty : 1.0 / (e.d * c.c_s);
    // Open: a direction rigid when closed may soften when open (c_open > c); glued edges stay glued.
    e.k_n_open = e.glued ? inf : c.c_n_open > 0 ? 1.0 / (e.d * c.c_n_open) : penalty;
    e.k_s_open = e.glued ? inf : c.c_s_open > 0 ? 1.0 / (e.d * c.c_s_open) : penalty;
    out.glued += e.glued ? 1 : 0;
    out.stiffened += !e.glued && (rigid_n || rigid_s) ? 1 : 0;
    out.sum_length += e.length;
    if (!rigid_n) out.sum_length_compliance_n += e.length / e.k_n;
    if (!rigid_s) out.sum_length_compliance_s += e.length / e.k_s;
    out.edges.push_back(e);
  }
  return out;
}

}  // namespace rbdem::compare
