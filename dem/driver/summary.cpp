// From a run's record to its result. See summary.hpp.
#include "dem/driver/summary.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "dem/materials.hpp"
#include "dem/specimen_mesh.hpp"

namespace rbdem {

namespace {
// The quasi-static verdict's limits (docs/theory.md, section 8 asks for about 1 % force agreement; explicit samples
// on a rising branch of a coarse specimen scatter by a few per cent even at quasi-static rates, hence 5 %).
constexpr double quasi_static_force_mismatch = quasi_static_force_mismatch_limit;
constexpr double quasi_static_kinetic_ratio = 0.05;
}  // namespace

CrackCounts count_cracks(const std::vector<Crack>& cracks) {
  CrackCounts c;
  for (const auto& k : cracks) {
    const bool shear = k.mode == BreakMode::shear;
    if (k.kind == BondKind::rock) (shear ? c.rock_shear : c.rock_tensile)++;
    else (shear ? c.joint_shear : c.joint_tensile)++;
  }
  return c;
}

std::vector<MaterialCracks> count_cracks_by_material(const std::vector<Crack>& cracks, const Specimen& specimen) {
  std::array<MaterialCracks, material_count> all{};
  for (std::size_t k = 0; k < material_count; ++k) all[k].material = material_name[k];
  for (const auto id : specimen.bonds.material) ++all[id].bonds;
  for (const auto& c : cracks) {
    MaterialCracks& mc = all[specimen.bonds.material[std::size_t(c.bond)]];
    ++(c.mode == BreakMode::shear ? mc.shear : mc.tensile);
  }
  std::vector<MaterialCracks> out;
  for (const auto& mc : all)
    if (mc.bonds > 0) out.push_back(mc);
  return out;
}

namespace {

// The principal axes of a symmetric 3 x 3 tensor sum w v v^T, eigenvalues ascending: column 0 is the axis of least
// spread, column 2 of the most.
Eigen::Matrix3d principal_axes(const Eigen::Matrix3d& t) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(t).eigenvectors();
}

std::array<double, 3> column(const Eigen::Matrix3d& m, int c) { return {m(0, c), m(1, c), m(2, c)}; }

// 3D: the dip of a mesh's joint faces, from the area-weighted orientation tensor of their normals (its principal
// axis is the mean normal, whatever each face's sign).
double joint_dip_deg3(const Specimen& specimen, double fallback) {
  Eigen::Matrix3d t = Eigen::Matrix3d::Zero();
  bool any = false;
  for (std::size_t b = 0; b < specimen.num_bonds(); ++b) {
    if (specimen.bonds.kind[b] != BondKind::joint) continue;
    const Eigen::Vector3d n(specimen.normal(b, 0), specimen.normal(b, 1), specimen.normal(b, 2));
    t += specimen.bonds.size[b] * n * n.transpose(), any = true;
  }
  if (!any) return fallback;
  return plane_orientation_deg(column(principal_axes(t), 2)).dip_deg;
}

}  // namespace

double joint_dip_deg(const Specimen& specimen, double fallback) {
  if (specimen.dim == 3) return joint_dip_deg3(specimen, fallback);
  // The mean of the doubled angles (an axial mean: a joint edge at theta and theta + 180 deg is the same line).
  double c = 0, s = 0;
  const auto& N = specimen.bonds;
  for (std::size_t b = 0; b < specimen.num_bonds(); ++b) {
    if (N.kind[b] != BondKind::joint) continue;
    // the edge direction, perpendicular to the bond normal
    const double along = std::atan2(-specimen.normal(b, 0), specimen.normal(b, 1));
    c += N.size[b] * std::cos(2.0 * along), s += N.size[b] * std::sin(2.0 * along);
  }
  if (std::hypot(c, s) <= 0) return fallback;
  return std::abs(0.5 * std::atan2(s, c) * 180.0 / std::numbers::pi);  // from (-90, 90]
}

std::string mesh_scale_warning(const std::string& file, double span) {
  if (span >= 1e-3 && span <= 1.0) return {};
  return fmt::format("the mesh {} spans {:.4g} m: its coordinates are read in metres and a lab specimen spans 1 mm to "
                     "1 m, so it is likely {}: scale it by {:g} (gmsh: Mesh.ScalingFactor when saving); the run goes "
                     "on at {:.4g} m",
                     file, span, span > 1.0 ? "drawn in millimetres" : "drawn in kilometres or scaled twice",
                     span > 1.0 ? 1e-3 : 1e3, span);
}

bool non_persistent(const Scene& scene) {
  return (scene.joint_set.enabled && scene.joint_set.persistence < 1.0) ||
         (scene.joint_set2.enabled && scene.joint_set2.persistence < 1.0);
}

std::string classify_failure(const std::vector<Crack>& cracks, const Specimen& specimen, double dip_deg,
                             double dip2_deg, bool bridges) {
  if (cracks.empty()) return "intact";
  // Per joint (a straight line of joint edges: one interface, one line n . x = r): its length and how much of it
  // broke, by mode. The pieces of a non-persistent joint count as one joint; a through-going joint between two
  // layers is one line too.
  std::map<std::array<long, 4>, std::array<double, 3>> joints;  // total, broken in shear, broken in tension
  const auto& N = specimen.bonds;
  const auto& layer = specimen.blocks.layer;
  const double scale = std::max(specimen.width(), specimen.height());
  auto joint_of = [&](std::size_t b) {
    const int a = layer[std::size_t(N.i[b])], c = layer[std::size_t(N.j[b])];
    const int f = N.interface[b];
    if (f < 0) return std::array<long, 4>{-1, std::min(a, c), std::max(a, c), 0};  // between layers of a user mesh
    if (specimen.dim == 3) {  // a plane n . x = r: its orientation (one sign per plane) and its distance
      const std::array<double, 3> n = upward_normal({specimen.normal(b, 0), specimen.normal(b, 1), specimen.normal(b, 2)});
      double r = 0;
      for (int k = 0; k < 3; ++k) r += n[std::size_t(k)] * specimen.midpoint(b, k);
      // The orientation as the upward normal's horizontal components (n_z follows): no angle to wrap around.
      const long ox = std::lround(n[0] * 1e4) + 20000, oy = std::lround(n[1] * 1e4) + 20000;
      return std::array<long, 4>{f, ox * 100000 + oy, std::lround(r / (1e-4 * scale)), 1};
    }
    double nx = specimen.normal(b, 0), ny = specimen.normal(b, 1);
    if (ny < 0 || (ny == 0 && nx < 0)) nx = -nx, ny = -ny;  // one sign per line
    const double r = nx * specimen.midpoint(b, 0) + ny * specimen.midpoint(b, 1);
    const double angle = std::atan2(ny, nx);
    return std::array<long, 4>{f, std::lround(angle * 1e3), std::lround(r / (1e-4 * scale)), 1};
  };
  auto second_set = [&](const std::array<long, 4>& id) {
    return id[0] >= 0 && specimen.interface_names[std::size_t(id[0])] == joint_set_group[1];
  };
  for (std::size_t b = 0; b < specimen.num_bonds(); ++b)
    if (N.kind[b] == BondKind::joint) joints[joint_of(b)][0] += N.size[b];
  double rock_t = 0, rock_s = 0, joint_broken = 0;
  for (const auto& k : cracks) {
    const std::size_t b = std::size_t(k.bond);
    const bool shear = k.mode == BreakMode::shear;
    if (k.kind == BondKind::joint) joints[joint_of(b)][shear ? 1 : 2] += N.size[b], joint_broken += N.size[b];
    else (shear ? rock_s : rock_t) += N.size[b];
  }
  // A joint broken along most of its length failed as a plane. It slid if it was broken in shear and the load
  // resolves a large shear stress on it: tau / sigma = sin(2 beta) / 2 >= 1/4, i.e. 15 <= beta <= 75 deg (at 75 deg
  // the paper scene's joints break in shear over their whole length, as Jaeger's slip range 30 < beta < 90 has
  // it). At steeper and flatter dips a broken joint has opened: splitting along the layers (the paper's cleavage
  // at 90 deg). A set dipping beyond 90 deg acts as one at 180 - beta.
  auto shear_loaded = [](double dip) {
    const double b = dip > 90.0 ? 180.0 - dip : dip;
    return b >= 15.0 && b <= 75.0;
  };
  bool slipped = false, opened = false;
  for (const auto& [id, len] : joints) {
    if (len[1] + len[2] < 0.5 * len[0]) continue;
    if (len[1] >= len[2] && shear_loaded(second_set(id) ? dip2_deg : dip_deg)) slipped = true;
    else opened = true;
  }
  // Non-persistent joints: a failure path that runs as much through the rock bridges as along the joints.
  if (bridges && (slipped || opened) && rock_t + rock_s >= 0.5 * joint_broken) return "bridge_fracture";
  if (slipped) return "shear_slip_along_joints";
  if (opened) return "splitting_along_layers";
  if (rock_t >= rock_s) return dip_deg >= 60.0 ? "splitting_along_layers" : "splitting_across_layers";
  return "shear_through_rock";
}

PlaneOrientation crack_band_plane(const std::vector<Crack>& cracks) {
  constexpr double undefined = std::numeric_limits<double>::quiet_NaN();
  double w = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& k : cracks) w += k.size, mean += k.size * Eigen::Vector3d(k.position[0], k.position[1], k.position[2]);
  if (cracks.size() < 3 || !(w > 0)) return {undefined, undefined};
  mean /= w;
  Eigen::Matrix3d t = Eigen::Matrix3d::Zero();
  for (const auto& k : cracks) {
    const Eigen::Vector3d d = Eigen::Vector3d(k.position[0], k.position[1], k.position[2]) - mean;
    t += k.size * d * d.transpose();
  }
  return plane_orientation_deg(column(principal_axes(t), 0));  // the band's normal: the direction of least spread
}

double crack_band_angle_deg(const std::vector<Crack>& cracks) {
  double w = 0, mx = 0, my = 0;
  for (const auto& k : cracks) {
    const double L = k.size;
    w += L, mx += L * k.position[0], my += L * k.position[1];
  }
  if (w <= 0) return 0.0;
  mx /= w, my /= w;
  double sxx = 0, syy = 0, sxy = 0;
  for (const auto& k : cracks) {
    const double L = k.size, dx = k.position[0] - mx, dy = k.position[1] - my;
    sxx += L * dx * dx, syy += L * dy * dy, sxy += L * dx * dy;
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy) * 180.0 / std::numbers::pi;  // major axis
  return std::abs(angle);
}

void summarize(const Scene& scene, const Specimen& specimen, const LoadingProtocol& protocol,
               const TestRecord& record, TestResult& r) {
  const double peak = record.peak;
  const CurvePoint& at_peak = record.at_peak;
  r.peak_stress = peak;
  r.strain_at_peak = at_peak.strain;
  const double mean_force = 0.5 * (at_peak.stress_top + at_peak.stress_bottom);
  r.platen_force_mismatch_at_peak =
      mean_force > 0 ? std::abs(at_peak.stress_top - at_peak.stress_bottom) / mean_force : 0.0;
  // The quasi-static check: platen forces agree while loading (explicit samples on the rising branch between 20 %
  // and 95 % of the peak; the first explicit sample if the elastic start skipped them). At the peak a brittle
  // failure is dynamic by nature: that value is reported separately.
  r.platen_force_mismatch = 0.0;
  const CurvePoint* first_explicit = nullptr;
  bool any = false;
  for (const auto& p : r.curve) {
    if (p.step <= 0 || p.strain >= at_peak.strain) continue;
    if (!first_explicit) first_explicit = &p;
    if (p.stress() < 0.2 * peak || p.stress() > 0.95 * peak) continue;
    any = true;
    r.platen_force_mismatch = std::max(r.platen_force_mismatch, std::abs(p.stress_top - p.stress_bottom) / p.stress());
    if (p.strain_energy > 0) r.kinetic_to_strain_loading = std::max(r.kinetic_to_strain_loading, p.kinetic / p.strain_energy);
  }
  if (!any && first_explicit && first_explicit->stress() > 0) {
    r.platen_force_mismatch = std::abs(first_explicit->stress_top - first_explicit->stress_bottom) / first_explicit->stress();
    if (first_explicit->strain_energy > 0) r.kinetic_to_strain_loading = first_explicit->kinetic / first_explicit->strain_energy;
  }
  r.kinetic_to_strain_at_peak = at_peak.strain_energy > 0 ? at_peak.kinetic / at_peak.strain_energy : 0.0;
  // The verdict: platen forces within 5 % and kinetic energy below 5 % of the strain energy while loading.
  // Brittle failure at the peak is dynamic by nature and does not count against it.
  {
    std::vector<std::string> why;
    if (!(r.platen_force_mismatch <= quasi_static_force_mismatch))
      why.push_back(fmt::format("platen forces differ by {:.1f} % while loading (limit {:.0f} %)",
                                100.0 * r.platen_force_mismatch, 100.0 * quasi_static_force_mismatch));
    if (!(r.kinetic_to_strain_loading <= quasi_static_kinetic_ratio))
      why.push_back(fmt::format("kinetic energy is {:.1f} % of the strain energy while loading (limit {:.0f} %)",
                                100.0 * r.kinetic_to_strain_loading, 100.0 * quasi_static_kinetic_ratio));
    if (peak <= 0) why.push_back("the platens carried no load");
    r.quasi_static = why.empty();
    for (std::size_t k = 0; k < why.size(); ++k) r.quasi_static_reason += (k ? "; " : "") + why[k];
    if (!r.quasi_static) r.quasi_static_reason += ": lower loading.platen_velocity or raise numerics.damping";
  }
  // Secant modulus at 50 % of the peak, interpolated on the pre-peak curve.
  for (std::size_t k = 1; k < r.curve.size() && r.curve[k].strain <= at_peak.strain; ++k) {
    const double s0 = r.curve[k - 1].stress(), s1 = r.curve[k].stress();
    if (s1 >= 0.5 * peak && s0 < 0.5 * peak) {
      const double f = (0.5 * peak - s0) / (s1 - s0);
      const double e = r.curve[k - 1].strain + f * (r.curve[k].strain - r.curve[k - 1].strain);
      r.youngs_modulus = e > 0 ? 0.5 * peak / e : 0.0;
      break;
    }
  }
  r.crack_counts = count_cracks(r.cracks);
  r.cracks_by_material = count_cracks_by_material(r.cracks, specimen);
  // A user mesh's layers have the dip its joint edges have, not the scene's joint_set.dip_deg.
  const double dip =
      scene.mesh.file.empty() ? scene.joint_set.dip_deg : joint_dip_deg(specimen, scene.joint_set.dip_deg);
  r.joint_dip_deg = dip;
  r.failure_mode = classify_failure(r.cracks, specimen, dip, second_set_dip_deg(scene, scene.joint_set.dip_deg),
                                    non_persistent(scene));
  const PlaneOrientation band = specimen.dim == 3 ? crack_band_plane(r.cracks)  // 3D: a plane, with its azimuth
                                                  : PlaneOrientation{crack_band_angle_deg(r.cracks), undefined_signal};
  r.crack_band_angle_deg = band.dip_deg, r.crack_band_dip_direction_deg = band.dip_direction_deg;
  double t_len = 0, all = 0;
  for (const auto& k : r.cracks) {
    all += k.size;
    if (k.mode == BreakMode::tensile) t_len += k.size;
  }
  r.tensile_fraction = all > 0 ? t_len / all : 0.0;
  // The signals (docs/theory.md, section 10).
  const double floor = protocol.stress_floor();
  if (protocol.lateral_signals()) {
    r.poisson_ratio_at_half_peak = poisson_ratio_at_half_peak(r.curve, peak, at_peak.strain, floor);
    r.crack_damage_stress = crack_damage_stress(r.curve, at_peak.strain, specimen.dim);
  }
  r.crack_initiation_stress = crack_initiation_stress(r.curve, r.cracks, peak, at_peak.strain);
  r.residual_stress = residual_stress(r.curve, at_peak.strain, r.stop_reason);
}

void crack_statistics(const Specimen& specimen, TestResult& r) {
  r.crack_rate = crack_rate(r.cracks, r.curve.empty() ? 0.0 : r.curve.back().strain);
  r.fragments = fragments(specimen, r.cracks);
  if (specimen.dim == 3) r.crack_rose = crack_rose3(r.cracks);
}

}  // namespace rbdem
