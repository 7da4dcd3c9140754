// The elastic gate: DEM static moduli against Amadei and the FE twin. See elastic_gate.hpp.
#include "compare/gate/elastic_gate.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "mesh/trimesh.hpp"

#ifdef RBDEM_HAVE_CONTINUUM
#include "continuum/fe_model.hpp"
#endif

namespace rbdem::compare {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Runs job(k) for k in [0, n) on up to `threads` threads; rethrows the first exception.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& job) {
  const std::size_t workers = std::min<std::size_t>(n, std::size_t(std::max(threads, 1)));
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&]() {
    for (std::size_t k = next++; k < n; k = next++) {
      try {
        job(k);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// One DEM measurement: the mesh (kept for the FE stage), the virtual test and, with fields, the displacements.
struct DemJob {
  double beta_deg = 0;
  bool intact = false;
  TriMesh mesh;
  VirtualTest test;
  JointBondStats joints;
  std::vector<double> x, y, area, ux, uy;  // block centroids, areas and displacements (fields only)
};

std::size_t find_angle(const std::vector<double>& betas, double beta) {
  for (std::size_t k = 0; k < betas.size(); ++k)
    if (std::abs(betas[k] - beta) < 1e-9) return k;
  return betas.size();
}

#ifdef RBDEM_HAVE_CONTINUUM
// Area-weighted mean of v.
double mean(const std::vector<double>& v, const std::vector<double>& w) {
  double s = 0, sw = 0;
  for (std::size_t k = 0; k < v.size(); ++k) s += w[k] * v[k], sw += w[k];
  return sw > 0 ? s / sw : 0.0;
}
#endif

std::string gpa(double v) { return std::isfinite(v) ? fmt::format("{:8.2f}", v / 1e9) : fmt::format("{:>8}", "-"); }
std::string pct(double v) { return std::isfinite(v) ? fmt::format("{:+7.2f}", 100.0 * v) : fmt::format("{:>7}", "-"); }

nlohmann::json constants_json(const theory::TIConstants& c) {
  return {{"E", c.E}, {"nu", c.nu}, {"E_prime", c.E_prime}, {"nu_prime", c.nu_prime}, {"G_prime", c.G_prime}};
}

// NaN is not JSON: write null.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

const char* measure_name(GateMeasure m) { return m == GateMeasure::gauge ? "dem_gauge" : "dem_static"; }

ElasticReport run_elastic_gate(const Scene& scene_in, const ElasticGateOptions& options) {
  const auto t0 = Clock::now();
  if (!scene_in.mesh.file.empty())
    throw SceneError(fmt::format("the elastic gate re-meshes the specimen at beta = 0, 15, ..., 90 deg and cannot do "
                                 "that with a user mesh (mesh.file = \"{}\"): run it on the generated specimen (no --mesh, "
                                 "mesh.file = \"\") with the same materials",
                                 scene_in.mesh.file));
  for (double b : options.fit_betas)
    if (find_angle(options.betas, b) == options.betas.size())
      throw std::invalid_argument(fmt::format("elastic gate: the fit angle {} deg is not among the angles run", b));
  const Scene scene = elastic_test_scene(scene_in);
  const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  std::mutex log_mutex;  // the angles report from worker threads
  auto log = [&](const std::string& s) {
    const std::lock_guard<std::mutex> lock(log_mutex);
    if (options.log) options.log(s);
  };

  ElasticReport rep;
  rep.plane = theory::plane_from_string(scene.specimen.model);
  rep.mesh_size = scene.mesh.size;
  rep.gate.tolerance = scene.elastic.tolerance;
  rep.gate.measure = options.measure;

  // Stage 1: mesh and solve the DEM at every angle, and the unjointed specimen (gmsh runs one mesh at a time;
  // the static solves overlap it).
  std::vector<DemJob> jobs(options.betas.size() + 1);
  for (std::size_t k = 0; k < options.betas.size(); ++k) jobs[k].beta_deg = options.betas[k];
  jobs.back().intact = true;
  const auto t_dem = Clock::now();
  parallel_for(jobs.size(), threads, [&](std::size_t k) {
    DemJob& job = jobs[k];
    Scene s = scene;
    s.joint_set.dip_deg = job.beta_deg;
    if (job.intact) s.joint_set.enabled = false;
    job.mesh = make_mesh(s);
    const Topology topo = build_topology(job.mesh, s.specimen.thickness, s.rock.density);
    StaticResult state;
    job.test = virtual_test(topo, s, job.beta_deg, options.end_fraction, options.fields ? &state : nullptr);
    job.joints.add(topo);
    if (options.fields && !job.intact) {
      job.x = topo.blocks.cx, job.y = topo.blocks.cy, job.area = topo.blocks.area;
      job.ux = std::move(state.ux), job.uy = std::move(state.uy);
    }
    log(fmt::format("  DEM {:<10} {:>6} blocks, E_static {:7.2f} GPa, E_gauge {:7.2f} GPa, {:.2f} s",
                    job.intact ? "intact" : fmt::format("beta {:g}", job.beta_deg), job.test.blocks,
                    job.test.platen_modulus / 1e9, job.test.gauge_modulus / 1e9, job.test.solve_seconds));
  });
  rep.dem_seconds = seconds_since(t_dem);

  // Stage 2: the constants.
  std::vector<VirtualTest> fit_tests;
  for (double b : options.fit_betas) fit_tests.push_back(jobs[find_angle(options.betas, b)].test);
  rep.dem = fit_compliance(fit_tests, rep.plane);
  rep.fit_betas = options.fit_betas;
  rep.intact = jobs.back().test;
  rep.intact_constants = isotropic_constants(rep.intact, rep.plane);
  JointBondStats joints;
  for (std::size_t k = 0; k + 1 < jobs.size(); ++k) joints.merge(jobs[k].joints);
  rep.goodman = goodman_estimate(scene, rep.intact_constants, joints.mean_d());

  rep.angles.resize(options.betas.size());
  for (std::size_t k = 0; k < options.betas.size(); ++k) {
    ElasticAngle& a = rep.angles[k];
    const DemJob& job = jobs[k];
    a.beta_deg = job.beta_deg;
    a.test = job.test;
    a.dem_static = job.test.platen_modulus;
    a.dem_gauge = job.test.gauge_modulus;
    a.amadei = theory::apparent_modulus(rep.dem.constants, a.beta_deg, rep.plane);
    a.amadei_goodman = theory::apparent_modulus(rep.goodman.constants, a.beta_deg, rep.plane);
  }

  // Stage 3: the FE twin on the same meshes.
#ifdef RBDEM_HAVE_CONTINUUM
  if (options.with_fe) {
    rep.fe_available = true;
    const auto t_fe = Clock::now();
    const bool dem_ok = rep.dem.admissible, goodman_ok = rep.goodman.constants.admissible();
    parallel_for(rep.angles.size(), threads, [&](std::size_t k) {
      ElasticAngle& a = rep.angles[k];
      const DemJob& job = jobs[k];
      const auto t = Clock::now();
      continuum::FeOptions fo;
      fo.plane = rep.plane;
      fo.platens = continuum::Platens::frictionless;
      fo.platen_displacement = job.test.platen_displacement;
      fo.fields = options.fields;
      if (dem_ok) {
        const auto fe = continuum::solve_elastic(job.mesh, rep.dem.constants, a.beta_deg, scene.specimen.thickness, fo);
        a.fe = fe.apparent_modulus;
        if (options.fields) {
          // Same platen displacement in both models; the rigid x translation removed from each.
          AngleFields& f = a.fields;
          f.x = job.x, f.y = job.y, f.dem_ux = job.ux, f.dem_uy = job.uy, f.fe_ux = fe.ux, f.fe_uy = fe.uy;
          const double mdem = mean(f.dem_ux, job.area), mfe = mean(f.fe_ux, job.area);
          double diff = 0, norm = 0;
          for (std::size_t b = 0; b < f.x.size(); ++b) {
            f.dem_ux[b] -= mdem, f.fe_ux[b] -= mfe;
            diff += job.area[b] * (std::pow(f.dem_ux[b] - f.fe_ux[b], 2) + std::pow(f.dem_uy[b] - f.fe_uy[b], 2));
            norm += job.area[b] * (f.fe_ux[b] * f.fe_ux[b] + f.fe_uy[b] * f.fe_uy[b]);
          }
          a.field_l2 = std::sqrt(diff / norm);
        }
      }
      if (goodman_ok) {
        fo.fields = false;
        a.fe_goodman = continuum::solve_elastic(job.mesh, rep.goodman.constants, a.beta_deg,
                                                scene.specimen.thickness, fo)
                           .apparent_modulus;
      }
      a.fe_seconds = seconds_since(t);
    });
    rep.fe_seconds = seconds_since(t_fe);
  }
#endif

  // The verdict.
  GateVerdict& g = rep.gate;
  for (const auto& a : rep.angles) {
    g.max_deviation_static = std::max(g.max_deviation_static, std::abs(a.deviation(GateMeasure::platen)));
    g.max_deviation_gauge = std::max(g.max_deviation_gauge, std::abs(a.deviation(GateMeasure::gauge)));
    const double d = std::abs(a.deviation(g.measure));
    if (!std::isnan(g.max_deviation) && !(d <= g.max_deviation))  // a NaN deviation is the worst and stays so
      g.max_deviation = d, g.worst_beta_deg = a.beta_deg;
  }
  g.passed = rep.dem.admissible && g.max_deviation <= g.tolerance;
  if (!rep.dem.admissible)
    g.reason = "the DEM-measured constants are not admissible (the compliance is not positive definite): the DEM "
               "specimen does not behave as a transversely isotropic continuum";
  else if (!g.passed)
    g.reason = fmt::format("|{} / amadei - 1| = {:.2f} % at beta = {:g} deg exceeds the tolerance {:.2f} %",
                           measure_name(g.measure), 100.0 * g.max_deviation, g.worst_beta_deg, 100.0 * g.tolerance);
  rep.seconds = seconds_since(t0);
  return rep;
}

nlohmann::json elastic_json(const ElasticReport& r, const Scene& scene) {
  nlohmann::json j;
  auto dem = constants_json(r.dem.constants);
  dem["a11"] = r.dem.a.a11, dem["a22"] = r.dem.a.a22, dem["a12"] = r.dem.a.a12, dem["a66"] = r.dem.a.a66;
  dem["fit_residual"] = r.dem.residual;
  dem["fit_max_residual"] = r.dem.max_residual;
  dem["admissible"] = r.dem.admissible;
  auto good = constants_json(r.goodman.constants);
  good["E_r"] = r.goodman.E_r, good["nu_r"] = r.goodman.nu_r;
  good["k_n"] = number(r.goodman.k_n), good["k_s"] = number(r.goodman.k_s);
  good["spacing"] = r.goodman.spacing, good["d_mean"] = r.goodman.d_mean;
  auto intact = constants_json(r.intact_constants);
  intact["dem_static_pa"] = r.intact.platen_modulus;
  intact["dem_gauge_pa"] = r.intact.gauge_modulus;
  j["constants"] = {{"dem", dem}, {"goodman", good}, {"intact", intact}};
  j["angles"] = nlohmann::json::array();
  for (const auto& a : r.angles) {
    nlohmann::json e = {
        {"beta_deg", a.beta_deg},
        {"amadei_pa", a.amadei},
        {"dem_static_pa", a.dem_static},
        {"fe_pa", number(a.fe)},
        {"fe_goodman_pa", number(a.fe_goodman)},
        {"dem_gauge_pa", a.dem_gauge},
        {"amadei_goodman_pa", a.amadei_goodman},
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
        {"blocks", a.test.blocks},
        {"bonds", a.test.bonds},
        {"joint_bonds", a.test.joint_bonds},
        {"open_linear_parts", a.test.open_bonds},
        {"sliding_linear_parts", a.test.sliding_bonds},
        {"static_solve_seconds", a.test.solve_seconds},
        {"fe_seconds", a.fe_seconds},
    };
    if (std::isfinite(a.field_l2)) e["field_l2"] = a.field_l2;
    if (!a.fields.x.empty())
      e["fields"] = {{"x", a.fields.x},         {"y", a.fields.y},         {"dem_ux", a.fields.dem_ux},
                     {"dem_uy", a.fields.dem_uy}, {"fe_ux", a.fields.fe_ux}, {"fe_uy", a.fields.fe_uy}};
    j["angles"].push_back(std::move(e));
  }
  const GateVerdict& g = r.gate;
  j["gate"] = {{"tolerance", g.tolerance},
               {"passed", g.passed},
               {"measure", measure_name(g.measure)},
               {"max_deviation", number(g.max_deviation)},
               {"worst_beta_deg", g.worst_beta_deg},
               {"max_deviation_dem_static", number(g.max_deviation_static)},
               {"max_deviation_dem_gauge", number(g.max_deviation_gauge)},
               {"reason", g.reason}};
  j["model"] = scene.specimen.model;
  j["platens"] = "frictionless";  // whatever loading.platen_friction says: Amadei's and the FE's condition
  j["fe_available"] = r.fe_available;
  j["timing"] = {{"total_seconds", r.seconds}, {"dem_seconds", r.dem_seconds}, {"fe_seconds", r.fe_seconds}};
  j["scene"] = scene_json(scene);
  return j;
}

std::string elastic_table(const ElasticReport& r) {
  const GateVerdict& g = r.gate;
  std::string s = fmt::format(
      "elastic gate: DEM static moduli vs Amadei with the DEM-measured constants ({}, mesh {:g} mm, frictionless "
      "platens)\n",
      r.plane == theory::Plane::strain ? "plane strain" : "plane stress", 1e3 * r.mesh_size);
  s += " beta   Amadei  DEM stat DEM gauge       FE  FE Goodm | stat-Am gauge-Am   FE-Am FEGd-Am | field L2\n";
  s += "  deg      GPa       GPa       GPa      GPa       GPa |       %        %       %       % |        %\n";
  for (const auto& a : r.angles) {
    s += fmt::format("{:5g} {} {}  {} {}  {} | {} {}  {} {} | {}{}\n", a.beta_deg, gpa(a.amadei), gpa(a.dem_static),
                     gpa(a.dem_gauge), gpa(a.fe), gpa(a.fe_goodman), pct(a.deviation(GateMeasure::platen)),
                     pct(a.deviation(GateMeasure::gauge)), pct(a.fe / a.amadei - 1.0),
                     pct(a.fe_goodman / a.amadei - 1.0),
                     std::isfinite(a.field_l2) ? fmt::format("{:8.2f}", 100.0 * a.field_l2) : fmt::format("{:>8}", "-"),
                     !g.passed && a.beta_deg == g.worst_beta_deg ? "  <- worst" : "");
  }
  const auto& c = r.dem.constants;
  s += fmt::format("DEM constants:     E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa "
                   "(virtual tests at {} deg, fit residual {:.2f} %{})\n",
                   c.E / 1e9, c.nu, c.E_prime / 1e9, c.nu_prime, c.G_prime / 1e9, fmt::join(r.fit_betas, "/"),
                   100.0 * r.dem.residual, r.dem.admissible ? "" : ", NOT admissible");
  const auto& gc = r.goodman.constants;
  s += fmt::format("Goodman constants: E {:.2f} GPa, nu {:.3f}, E' {:.2f} GPa, nu' {:.3f}, G' {:.2f} GPa "
                   "(intact E_r {:.2f} GPa, nu_r {:.3f}; k_n {:.3g} Pa/m, k_s {:.3g} Pa/m, s {:g} m)\n",
                   gc.E / 1e9, gc.nu, gc.E_prime / 1e9, gc.nu_prime, gc.G_prime / 1e9, r.goodman.E_r / 1e9,
                   r.goodman.nu_r, r.goodman.k_n, r.goodman.k_s, r.goodman.spacing);
  s += fmt::format("gate on {} (the {}): max |E / E_Amadei - 1| = {:.2f} % at beta = {:g} deg, tolerance {:.2f} % "
                   "-> {}\n",
                   measure_name(g.measure),
                   g.measure == GateMeasure::gauge ? "interior-gauge modulus, platen contacts excluded"
                                                   : "platen-based modulus",
                   100.0 * g.max_deviation, g.worst_beta_deg, 100.0 * g.tolerance, g.passed ? "PASSED" : "FAILED");
  if (!g.passed) s += "  " + g.reason + "\n";
  return s;
}

}  // namespace rbdem::compare
