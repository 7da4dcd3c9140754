// The elastic gate in 3D: measurements and verdict. See elastic_gate3.hpp.
#include "compare/gate/elastic_gate3.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "common/parallel_map.hpp"
#include "dem/static3.hpp"
#include "theory/elasticity3.hpp"

#ifdef RBDEM_HAVE_CONTINUUM
#include "continuum/fe_3d.hpp"
#include "continuum/fe_joints3.hpp"
#endif

namespace rbdem::compare {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double azimuth(double deg) {
  const double a = std::fmod(deg, 360.0);
  return a < 0 ? a + 360.0 : a;
}

void check_scene(const Scene& scene) {
  if (scene.specimen.dimension != 3)
    throw SceneError(fmt::format("the 3D elastic gate was given a {}D scene: set specimen.dimension = 3",
                                 scene.specimen.dimension));
  if (!scene.mesh.file.empty())
    throw SceneError(fmt::format("mesh.file = \"{}\": the 3D elastic gate meshes the specimen at every dip, which a "
                                 "user mesh cannot follow; remove mesh.file (rbdem mesh reads it)",
                                 scene.mesh.file));
  if (scene.specimen.shape == "disc")
    throw SceneError("specimen.shape = \"disc\": rbdem elastic in 3D compresses a cylinder or a prism between its "
                     "platens (the moduli from the axial and lateral strains); use specimen.shape = \"cylinder\" or "
                     "\"prism\" (rbdem brazilian runs the disc)");
  if (scene.joint_set2.enabled)
    throw SceneError("joint_set2.enabled = true: rbdem elastic in 3D measures the five constants of one joint set "
                     "(transverse isotropy); set joint_set2.enabled = false");
}

#ifdef RBDEM_HAVE_CONTINUUM
// The joint faces of the dip's mesh as interfaces of the DEM's own joint compliance: a joint bond of centroid
// distance d (along the face normal) adds d c_n, d c_s over the rock bond it replaces (joint_compliance), so its
// face gets k_n = 1 / (d c_n), k_s = 1 / (d c_s); a joint no softer than the rock (c <= 0) is glued.
std::vector<continuum::InterfaceFace> dem_joint_faces(const TetMesh& mesh, const JointCompliance& c) {
  auto centroid = [&](int t) {
    std::array<double, 3> x{};
    for (int n : mesh.tets[std::size_t(t)])
      for (int k = 0; k < 3; ++k) x[std::size_t(k)] += 0.25 * mesh.nodes[std::size_t(n)][std::size_t(k)];
    return x;
  };
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<continuum::InterfaceFace> faces;
  for (const SharedFace& f : shared_faces(mesh)) {
    if (!f.joint) continue;
    const auto& a = mesh.nodes[std::size_t(f.nodes[0])];
    const auto& b = mesh.nodes[std::size_t(f.nodes[1])];
    const auto& e = mesh.nodes[std::size_t(f.nodes[2])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const auto ci = centroid(f.tets[0]), cj = centroid(f.tets[1]);
    const double d = std::abs(n[0] * (cj[0] - ci[0]) + n[1] * (cj[1] - ci[1]) + n[2] * (cj[2] - ci[2])) /
                     std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const bool soft = c.c_n > 0 && c.c_s > 0;
    faces.push_back({f.tets[0], f.tets[1], soft ? 1.0 / (d * c.c_n) : inf, soft ? 1.0 / (d * c.c_s) : inf});
  }
  return faces;
}
#endif

// The FE twins on the dip's mesh: with the DEM's constants, with Goodman's, and with the joints as interfaces in
// the jointed mesh's rock; NaN where the module is missing or the constants are not admissible (the table says
// which).
void fe_columns(Elastic3Angle& a, const TetMesh& mesh, const Elastic3Report& rep, const Scene& scene, double dd) {
#ifdef RBDEM_HAVE_CONTINUUM
  const auto t = Clock::now();
  if (rep.constants.dem.admissible()) {
    const continuum::Fe3Result fe = continuum::solve_elastic_3d(mesh, rep.constants.dem, a.beta_deg, dd);
    a.fe = fe.mean_strain_modulus, a.fe_platen = fe.apparent_modulus;
    a.fe_poisson_strike = fe.poisson_strike, a.fe_poisson_dip = fe.poisson_dip;
    a.fe_dofs = fe.dofs;
  }
  if (rep.constants.goodman.constants.admissible())
    a.fe_goodman = continuum::solve_elastic_3d(mesh, rep.constants.goodman.constants, a.beta_deg, dd)
                       .mean_strain_modulus;
  a.fe_seconds = since(t);
  if (!rep.constants.fabric_tests.empty() && rep.constants.fabric.admissible()) {
    const auto tj = Clock::now();
    const std::vector<continuum::InterfaceFace> faces = dem_joint_faces(mesh, joint_compliance(scene));
    const std::vector<theory::TIConstants> layers(std::max<std::size_t>(mesh.num_layers(), 1),
                                                  rep.constants.fabric);
    const continuum::JointedFe3Result fj =
        continuum::solve_elastic_3d_jointed(mesh, layers, a.beta_deg, dd, faces);
    a.fe_joints = fj.mean_strain_modulus, a.fe_joints_platen = fj.apparent_modulus;
    a.fe_joints_poisson_strike = fj.poisson_strike, a.fe_joints_poisson_dip = fj.poisson_dip;
    a.fe_joints_seconds = since(tj);
  }
#else
  (void)a, (void)mesh, (void)rep, (void)scene, (void)dd;
#endif
}

// The scene's specimen at dip beta (meshing is serial: gmsh holds one global model).
TetMesh mesh_angle(const Scene& scene, double beta, Elastic3Angle& a) {
  a.beta_deg = beta;
  SpecimenGeometry3 g = specimen_geometry3(scene);
  g.set1.dip_deg = beta;
  const auto t = Clock::now();
  TetMesh mesh = mesh_specimen3(g, scene.mesh.size);
  a.mesh_seconds = since(t);
  return mesh;
}

// The DEM's static solve, Amadei and the FE twins on one dip's mesh (thread-safe: no shared state).
void measure_angle(const Scene& scene, const TetMesh& mesh, const Elastic3Report& rep, bool with_fe,
                   Elastic3Angle& a) {
  const double beta = a.beta_deg, dd = rep.dip_direction_deg;
  const auto t = Clock::now();
  Static3Options o = static3_options(scene);
  o.dip_direction_deg = dd;
  const Static3Result r = solve_static3(mesh, o);
  a.dem_seconds = since(t);
  a.dem_static = r.fit_modulus, a.dem_platen = r.platen_modulus;
  a.dem_poisson_strike = r.poisson_strike, a.dem_poisson_dip = r.poisson_dip;
  a.blocks = r.blocks, a.bonds = r.rock_bonds + r.joint_bonds, a.joint_bonds = r.joint_bonds, a.dofs = r.dofs;
  const theory::Uniaxial3 am = theory::amadei_uniaxial_3d(rep.constants.dem, beta);
  a.amadei = am.modulus;
  a.amadei_poisson_strike = am.poisson_strike, a.amadei_poisson_dip = am.poisson_dip;
  a.amadei_goodman = theory::amadei_uniaxial_3d(rep.constants.goodman.constants, beta).modulus;
  if (rep.constants.goodman_fabric.admissible())
    a.amadei_goodman_fabric = theory::amadei_uniaxial_3d(rep.constants.goodman_fabric, beta).modulus;
  if (with_fe) fe_columns(a, mesh, rep, scene, dd);
}

void verdict(Elastic3Report& rep, double tolerance) {
  Gate3Verdict& g = rep.gate;
  g.tolerance = tolerance;
  g.comparison = rep.fe_available ? "fe" : "amadei";
  g.max_deviation = 0, g.max_deviation_amadei = 0;
  bool finite = true;
  for (const auto& a : rep.angles) {
    g.max_deviation_amadei = std::max(g.max_deviation_amadei, std::abs(a.deviation_amadei()));
    const double d = rep.fe_available ? a.deviation_fe() : a.deviation_amadei();
    if (!std::isfinite(d)) finite = false;
    else if (std::abs(d) >= g.max_deviation) g.max_deviation = std::abs(d), g.worst_beta_deg = a.beta_deg;
  }
  const std::string ref = rep.fe_available ? "the FE twin with the DEM's constants" : "Amadei with the DEM's constants";
  g.passed = finite && rep.constants.dem.admissible() && g.max_deviation <= tolerance;
  g.message = fmt::format("{}: DEM static {:.2f} % off {} at worst (beta = {:g} deg, tolerance {:.2f} %); Amadei "
                          "{:.2f} %",
                          g.passed ? "passed" : "FAILED", 100.0 * g.max_deviation, ref, g.worst_beta_deg,
                          100.0 * tolerance, 100.0 * g.max_deviation_amadei);
  if (g.passed) return;
  if (!rep.constants.dem.admissible())
    g.reason = "the DEM-measured constants are not admissible (the compliance is not positive definite): the "
               "virtual tests on the prisms disagree; check the bond materials and try a finer mesh.size";
  else
    g.reason = fmt::format("|dem_static / {} - 1| = {:.2f} % at beta = {:g} deg exceeds elastic.tolerance = {:.2f} "
                           "%: a coarse mesh scatters (a few % at 8 mm, docs/continuum.md); try a finer mesh.size, "
                           "or raise elastic.tolerance if the scatter is accepted",
                           rep.fe_available ? "fe" : "amadei", 100.0 * g.max_deviation, g.worst_beta_deg,
                           100.0 * tolerance);
}

}  // namespace

Elastic3Report run_elastic_gate3(const Scene& scene, const Elastic3Options& options) {
  check_scene(scene);
  const auto t0 = Clock::now();
  Elastic3Report rep;
  rep.shape = scene.specimen.shape;
  rep.mesh_size = scene.mesh.size;
  rep.dip_direction_deg = azimuth(scene.joint_set.dip_direction_deg);
#ifdef RBDEM_HAVE_CONTINUUM
  rep.fe_available = options.with_fe;
#endif
  auto log = [&](const std::string& s) {
    if (options.log) options.log(s);
  };
  const int threads =
      options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  rep.constants = measure_dem_constants3(scene, threads);
  rep.constants_seconds = rep.constants.seconds;
  log(fmt::format("constants: virtual tests on the {:g} x {:g} x {:g} mm prism in {:.2f} s",
                  1e3 * rep.constants.prism.width, 1e3 * rep.constants.prism.depth, 1e3 * rep.constants.prism.height,
                  rep.constants.seconds));
  rep.angles.resize(options.betas.size());
  std::vector<TetMesh> meshes;
  for (std::size_t k = 0; k < options.betas.size(); ++k)
    meshes.push_back(mesh_angle(scene, options.betas[k], rep.angles[k]));
  std::mutex log_mutex;
  parallel_map(rep.angles.size(), threads, [&](std::size_t k) {
    Elastic3Angle& a = rep.angles[k];
    measure_angle(scene, meshes[k], rep, rep.fe_available, a);
    const std::lock_guard<std::mutex> lock(log_mutex);
    log(fmt::format("beta {:g}: {} blocks, mesh {:.2f} s, DEM {:.2f} s, FE {:.2f} s", a.beta_deg, a.blocks,
                    a.mesh_seconds, a.dem_seconds, a.fe_seconds));
  });
  for (const auto& a : rep.angles)
    rep.mesh_seconds += a.mesh_seconds, rep.dem_seconds += a.dem_seconds, rep.fe_seconds += a.fe_seconds,
    rep.fe_joints_seconds += a.fe_joints_seconds;
  verdict(rep, scene.elastic.tolerance);
  rep.seconds = since(t0);
  return rep;
}

}  // namespace rbdem::compare
