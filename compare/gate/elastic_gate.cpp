// The elastic gate: DEM static moduli against the FE model with the joints (the verdict), Amadei and the homogenized
// FE twin. See elastic_gate.hpp; elastic_gate_report.cpp writes elastic.json and the table.
#include "compare/gate/elastic_gate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/parallel_map.hpp"
#include "dem/materials.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "mesh/trimesh.hpp"

#ifdef RBDEM_HAVE_CONTINUUM
#include "continuum/fe_joints.hpp"
#include "continuum/fe_model.hpp"
#endif

namespace rbdem::compare {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// One DEM measurement: the mesh (kept for the FE stage), the virtual test and, with fields, the displacements.
struct DemJob {
  double beta_deg = 0;
  bool intact = false;
  TriMesh mesh;
  Topology<2> topo;         // kept for the gauge of the FE model with the joints and its interfaces
  VirtualTest test;
  VirtualTest rock_test;    // the same mesh with the joint bonds given the rock's bond parameters
  VirtualTest rock2_test;   // the same with every bond given rock2's (with rock2 layers; on the intact job too)
  std::vector<std::uint8_t> rock2_layer;  // 1 for each layer id of rock2 (dem/materials.hpp)
  JointBondStats joints;
  std::vector<double> ux, uy;  // block displacements (fields only)
};

// Max of |d| over a column; NaN counts as the worst and stays.
double worse(double current, double d) {
  if (std::isnan(current)) return current;
  const double a = std::abs(d);
  return std::isnan(a) || a > current ? a : current;
}

// The same, remembering the dip of the worst.
void track(double& max, double& where, double d, double beta) {
  if (std::isnan(max)) return;
  const double a = std::abs(d);
  if (std::isnan(a) || a > max) max = a, where = beta;
}

// The scene at one dip; the unjointed specimen (intact) is one layer of the rock.
Scene dip_scene(const Scene& scene, double beta_deg, bool intact) {
  Scene s = scene;
  s.joint_set.dip_deg = beta_deg;
  if (intact) {
    s.joint_set.enabled = s.joint_set2.enabled = false;
    s.rock2.groups.clear();
    s.beds = BedsParams{};
  }
  return s;
}

// A rock of the layers: the same mesh with every bond (joints, and the layers of the other rock) given the bond
// parameters of `rock` (the scene's rock or rock2).
Scene layer_rock_scene(const Scene& s, const MaterialParams& rock) {
  Scene h = s;
  const MaterialParams m = rock;
  for (MaterialParams* p : {static_cast<MaterialParams*>(&h.rock), static_cast<MaterialParams*>(&h.joint),
                            static_cast<MaterialParams*>(&h.joint2), static_cast<MaterialParams*>(&h.rock2)})
    *p = m;
  return h;
}
Scene rock_joints_scene(const Scene& s) { return layer_rock_scene(s, s.rock); }

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

// The FE model with the joints on a dip's mesh: every layer `rock`, the joint bonds as interfaces, frictionless
// platens, the DEM's platen displacement; with `gauge` also the interior gauge at the block centroids.
// Unilateral joints (`unilateral`): like the DEM's joint bonds, an interface whose sides separate (mean normal jump
// > 0, the bond's centre in tension) loses its linear part and takes the open stiffness (k_n_open, k_s_open). The
// states are found by an active-set iteration: solve with every joint closed, open those that separate, close
// those that press, until no state changes (at most max_joint_state_solves solves). A joint whose normal
// traction k_n x opening is within 1e-6 of the applied stress keeps its state: at beta = 90 deg the joints carry
// no normal stress, and round-off would flip them back and forth without changing the modulus. Without it (the
// linear check) every joint stays closed.
struct JointsSolve {
  double gauge_modulus = std::numeric_limits<double>::quiet_NaN(), platen_modulus = 0;
  GaugeStrain gauge;
  std::size_t dofs = 0;
  std::size_t open_edges = 0;  // interfaces in the open state at the end
  int state_solves = 0;        // solves of the active-set iteration (1 when nothing opens)
  bool states_settled = true;
  std::vector<double> ux, uy;
};

constexpr int max_joint_state_solves = 20;

JointsSolve solve_joints(const DemJob& job, const theory::TIConstants& rock, const theory::TIConstants& rock2,
                         const JointInterfaces& f, theory::Plane plane, const ElasticGateOptions& o, bool gauge,
                         int refinement, bool unilateral) {
  int max_layer = 0;
  for (int l : job.mesh.layer) max_layer = std::max(max_layer, l);
  const std::size_t n_layers = std::max(job.mesh.num_layers(), std::size_t(max_layer) + 1);
  std::vector<continuum::InterfaceEdge> edges;
  edges.reserve(f.edges.size());
  for (const auto& e : f.edges) edges.push_back({e.node_a, e.node_b, e.k_n, e.k_s});
  continuum::JointedFeOptions jo;
  jo.plane = plane;
  jo.platens = continuum::Platens::frictionless;  // as the DEM's virtual test
  jo.platen_displacement = job.test.platen_displacement;
  jo.direct_dof_limit = o.joints_direct_dof_limit;
  jo.fields = gauge;
  jo.refinement = refinement;
  std::vector<theory::TIConstants> layers(n_layers, rock);  // each layer the constants of its rock
  for (std::size_t l = 0; l < n_layers && l < job.rock2_layer.size(); ++l)
    if (job.rock2_layer[l]) layers[l] = rock2;
  JointsSolve out;
  std::vector<char> open(edges.size(), 0);
  continuum::JointedFeResult r;
  for (;;) {
    r = continuum::solve_elastic_jointed(job.mesh, layers, job.beta_deg, edges, job.topo.thickness, jo);
    ++out.state_solves;
    if (!unilateral) break;
    bool changed = false;
    const double band = 1e-6 * std::abs(r.top_force) / (job.topo.width() * job.topo.thickness);  // Pa
    for (std::size_t k = 0; k < edges.size(); ++k) {
      if (std::isinf(edges[k].k_n)) continue;  // glued: its copies are tied, it neither opens nor closes
      const double traction = edges[k].k_n * r.interface_opening[k];  // Pa, tension positive
      const char now = traction > band ? 1 : traction < -band ? 0 : open[k];
      if (now == open[k]) continue;
      changed = true, open[k] = now;
      edges[k].k_n = now ? f.edges[k].k_n_open : f.edges[k].k_n;
      edges[k].k_s = now ? f.edges[k].k_s_open : f.edges[k].k_s;
    }
    if (!changed) break;
    if (out.state_solves == max_joint_state_solves) {
      out.states_settled = false;
      break;
    }
  }
  out.open_edges = std::size_t(std::count(open.begin(), open.end(), 1));
  out.platen_modulus = r.apparent_modulus;
  out.dofs = r.dofs;
  if (gauge) {
    // The DEM's measure: the same stress over the same interior gauge, the triangles' centroids being the blocks'.
    out.gauge = gauge_strain(job.topo, r.ux, r.uy, o.end_fraction);
    const double stress = -0.5 * (r.top_force + r.bottom_force) / (job.topo.width() * job.topo.thickness);
    out.gauge_modulus = stress / out.gauge.eps_yy;
    out.ux = std::move(r.ux), out.uy = std::move(r.uy);
  }
  return out;
}

// The linear check, run when the DEM misses the FE model with the joints: the DEM and the rock of its layers again
// with every linear part closed and sticking, and the FE model with the joints on that rock. Opening linear parts
// can only soften the DEM, so it decides (comparison "fe_joints_linear") when the linear DEM is within the
// tolerance and, wherever the DEM as it runs misses, it is softer than its linear self and none of its linear parts
// slides (sliding is a Coulomb effect of the friction, not excused here).
void linear_check(ElasticReport& rep, const std::vector<DemJob>& jobs, const std::vector<JointInterfaces>& interfaces,
                  const Scene& scene, const ElasticGateOptions& options, int threads) {
  const auto t0 = Clock::now();
  const bool gauge = rep.gate.measure == GateMeasure::gauge;
  const bool same_mesh = options.layer_rock == ElasticGateOptions::LayerRock::same_mesh;
  // A rock's constants, linear: on the dip's mesh (same_mesh) or on the unjointed specimen.
  auto linear_rock = [&](const Topology<2>& topo, const Scene& s, const MaterialParams& rock, double beta) {
    return isotropic_constants(virtual_test(topo, layer_rock_scene(s, rock), beta, options.end_fraction, nullptr,
                                            true),
                               rep.plane);
  };
  const Scene unjointed = dip_scene(scene, 0, true);
  const theory::TIConstants intact =
      same_mesh ? rep.intact_constants : linear_rock(jobs.back().topo, unjointed, unjointed.rock, 0);
  const theory::TIConstants intact2 = same_mesh || !rep.two_rocks
                                          ? rep.intact2_constants
                                          : linear_rock(jobs.back().topo, unjointed, unjointed.rock2, 0);
  parallel_map(rep.angles.size(), threads, [&](std::size_t k) {
    ElasticAngle& a = rep.angles[k];
    const DemJob& job = jobs[k];
    const Scene s = dip_scene(scene, a.beta_deg, false);
    const VirtualTest dem = virtual_test(job.topo, s, a.beta_deg, options.end_fraction, nullptr, true);
    a.dem_linear = gauge ? dem.gauge_modulus : dem.platen_modulus;
    const theory::TIConstants rock = same_mesh ? linear_rock(job.topo, s, s.rock, a.beta_deg) : intact;
    const theory::TIConstants rock2 =
        !rep.two_rocks ? rock : same_mesh ? linear_rock(job.topo, s, s.rock2, a.beta_deg) : intact2;
    if (rock.admissible() && rock2.admissible()) {
      const JointsSolve fj = solve_joints(job, rock, rock2, interfaces[k], rep.plane, options, gauge,
                                          options.joints_refinement, false);
      a.fe_joints_linear = gauge ? fj.gauge_modulus : fj.platen_modulus;
    }
  });
  rep.linear_check_run = true;
  rep.linear_check_seconds = seconds_since(t0);
  GateVerdict& g = rep.gate;
  double worst = 0, where = 0;
  bool softer = true, sliding = false;
  for (const auto& a : rep.angles) {
    track(worst, where, a.dem_linear / a.fe_joints_linear - 1.0, a.beta_deg);
    if (!(std::abs(a.deviation_joints(g.measure)) <= g.tolerance)) {
      softer = softer && (gauge ? a.dem_gauge : a.dem_static) < a.dem_linear;
      sliding = sliding || a.test.sliding_bonds > 0;
    }
  }
  g.max_deviation_linear = worst;
  rep.linear_check_sliding = sliding;
  if (worst <= g.tolerance && softer && !sliding) {
    g.comparison = "fe_joints_linear";
    g.passed = true;
    g.max_deviation = worst, g.worst_beta_deg = where;
  }
}

// Removes the rigid x translation (area-weighted mean u_x) from each field and returns the relative L2 difference
// |u_a - u_b| / |u_b| (area-weighted).
double relative_l2(std::vector<double>& ax, const std::vector<double>& ay, std::vector<double>& bx,
                   const std::vector<double>& by, const std::vector<double>& area) {
  const double ma = mean(ax, area), mb = mean(bx, area);
  double diff = 0, norm = 0;
  for (std::size_t k = 0; k < ax.size(); ++k) {
    ax[k] -= ma, bx[k] -= mb;
    diff += area[k] * (std::pow(ax[k] - bx[k], 2) + std::pow(ay[k] - by[k], 2));
    norm += area[k] * (bx[k] * bx[k] + by[k] * by[k]);
  }
  return std::sqrt(diff / norm);
}
#endif

// The progress log, serialised: the dips report from worker threads.
class SerialLog {
 public:
  explicit SerialLog(const std::function<void(const std::string&)>& sink) : sink_(sink) {}
  void operator()(const std::string& s) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (sink_) sink_(s);
  }

 private:
  const std::function<void(const std::string&)>& sink_;
  std::mutex mutex_;
};

// Throws when the scene or the options cannot be gated: a user mesh (the dips cannot be re-meshed) or a fit angle
// that is not run.
void check_gate_inputs(const Scene& scene_in, const ElasticGateOptions& options) {
  if (!scene_in.mesh.file.empty())
    throw SceneError(fmt::format("the elastic gate re-meshes the specimen at beta = 0, 15, ..., 90 deg and cannot do "
                                 "that with a user mesh (mesh.file = \"{}\"): run it on the generated specimen (no --mesh, "
                                 "mesh.file = \"\") with the same materials",
                                 scene_in.mesh.file));
  for (double b : options.fit_betas)
    if (find_angle(options.betas, b) == options.betas.size())
      throw std::invalid_argument(fmt::format("elastic gate: the fit angle {} deg is not among the angles run", b));
}

// One dip (or, with job.intact, the unjointed specimen): its mesh, topology and virtual test, with the rock of its
// layers (the joint bonds given the rock's bond parameters) when same_mesh_rock, and rock2's (every bond rock2's)
// when the scene has rock2 layers. Returns the progress line.
std::string measure_dip(DemJob& job, const Scene& scene, const ElasticGateOptions& options, bool same_mesh_rock) {
  const Scene s = dip_scene(scene, job.beta_deg, job.intact);
  const bool two_rocks = uses_rock2(scene);
  job.mesh = make_mesh(s);
  job.topo = build_topology(job.mesh, s.specimen.thickness, s.rock.density);
  if (!job.intact) job.rock2_layer = rock2_layers(job.topo, s);
  StaticResult state;
  job.test = virtual_test(job.topo, s, job.beta_deg, options.end_fraction, options.fields ? &state : nullptr);
  job.joints.add(job.topo);
  if (same_mesh_rock && !job.intact)
    job.rock_test = virtual_test(job.topo, rock_joints_scene(s), job.beta_deg, options.end_fraction);
  if (two_rocks && (same_mesh_rock || job.intact))
    job.rock2_test = virtual_test(job.topo, layer_rock_scene(s, scene.rock2), job.beta_deg, options.end_fraction);
  if (options.fields && !job.intact) job.ux = state.component(0), job.uy = state.component(1);
  const auto layer_rock = [](const char* name, const VirtualTest& t) {
    return t.S22 != 0 ? fmt::format("; {} E_gauge {:7.2f} GPa", name, t.gauge_modulus / 1e9) : std::string();
  };
  return fmt::format("  DEM {:<10} {:>6} blocks, E_static {:7.2f} GPa, E_gauge {:7.2f} GPa, {:.2f} s{}{}",
                     job.intact ? "intact" : fmt::format("beta {:g}", job.beta_deg), job.test.blocks,
                     job.test.platen_modulus / 1e9, job.test.gauge_modulus / 1e9, job.test.solve_seconds,
                     layer_rock("rock of the layers", job.rock_test), layer_rock("rock2", job.rock2_test));
}

// Stage 1: mesh and solve the DEM at every angle, and the unjointed specimen (the last job; gmsh runs one mesh at a
// time, the static solves overlap it). With the FE model with the joints, each dip's mesh is solved a second time
// with the joint bonds given the rock's bond parameters: the rock of its layers.
std::vector<DemJob> measure_dips(const Scene& scene, const ElasticGateOptions& options, bool same_mesh_rock,
                                 int threads, SerialLog& log) {
  std::vector<DemJob> jobs(options.betas.size() + 1);
  for (std::size_t k = 0; k < options.betas.size(); ++k) jobs[k].beta_deg = options.betas[k];
  jobs.back().intact = true;
  parallel_map(jobs.size(), threads,
               [&](std::size_t k) { log(measure_dip(jobs[k], scene, options, same_mesh_rock)); });
  return jobs;
}

// Stage 2: the constants: the DEM-measured ones (fit over the fit angles), the intact rock's and Goodman's.
void fit_constants(ElasticReport& rep, const std::vector<DemJob>& jobs, const Scene& scene,
                   const ElasticGateOptions& options) {
  std::vector<VirtualTest> fit_tests;
  for (double b : options.fit_betas) fit_tests.push_back(jobs[find_angle(options.betas, b)].test);
  rep.dem = fit_compliance(fit_tests, rep.plane);
  rep.fit_betas = options.fit_betas;
  rep.intact = jobs.back().test;
  rep.intact_constants = isotropic_constants(rep.intact, rep.plane);
  rep.two_rocks = uses_rock2(scene);
  if (rep.two_rocks) rep.intact2_constants = isotropic_constants(jobs.back().rock2_test, rep.plane);
  JointBondStats joints;
  for (std::size_t k = 0; k + 1 < jobs.size(); ++k) joints.merge(jobs[k].joints);
  rep.goodman = goodman_estimate(scene, rep.intact_constants, joints.mean_d());
}

// The joint interfaces of every dip (per bond, with its own d) and their summary (rep.interfaces).
std::vector<JointInterfaces> dip_interfaces(ElasticReport& rep, const std::vector<DemJob>& jobs, const Scene& scene) {
  std::vector<JointInterfaces> interfaces(jobs.size() - 1);
  JointInterfaces all;
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    interfaces[k] = joint_interfaces(jobs[k].topo, scene, rep.intact_constants.E);
    JointInterfaces stats = interfaces[k];
    stats.edges.clear();
    all.merge(stats);
  }
  InterfaceSummary& is = rep.interfaces;
  const JointCompliance c = joint_compliance(scene);
  is.c_n = c.c_n, is.c_s = c.c_s;
  is.k_n = all.mean_k_n(), is.k_s = all.mean_k_s();
  is.glued = all.glued, is.stiffened = all.stiffened;
  for (const auto& f : interfaces) is.edges += f.edges.size();
  if (is.glued > 0)
    is.note = fmt::format("joints not softer than the rock (E*_j {:.3g} Pa >= E*_r {:.3g} Pa and kappa_j / E*_j <= "
                          "kappa_r / E*_r): all {} joint edges glued in the FE model with the joints (no extra "
                          "compliance)",
                          scene.joint.effective_modulus, scene.rock.effective_modulus, is.glued);
  else if (is.stiffened > 0)
    is.note = fmt::format("joints not softer than the rock in {} (c_n = {:.3g}, c_s = {:.3g} 1/Pa): that direction "
                          "is rigid (penalty 1e4 E_r / d) on all {} joint edges",
                          c.c_n > 0 ? "shear" : "the normal direction", c.c_n, c.c_s, is.stiffened);
  return interfaces;
}

// Salamon's interbedded medium (theory::interbedded) of the rocks `rock`, `rock2` in the beds' thickness fractions,
// with the mean joint stiffness of one dip's interfaces: Amadei's apparent modulus at beta.
double interbedded_modulus(const theory::TIConstants& rock, const theory::TIConstants& rock2, const BedSequence& beds,
                           const JointInterfaces& joints, const Scene& scene, double beta_deg, theory::Plane plane) {
  double h1 = 0, h2 = 0;
  for (std::size_t k = 0; k < beds.rock2.size(); ++k) (beds.rock2[k] ? h2 : h1) += beds.thickness[k];
  if (!rock.admissible() || !rock2.admissible()) return std::numeric_limits<double>::quiet_NaN();
  const auto c = theory::interbedded(rock.E, rock.nu, h1, rock2.E, rock2.nu, h2, joints.mean_k_n(),
                                     joints.mean_k_s(), scene.joint_set.spacing);
  return theory::apparent_modulus(c, beta_deg, plane);
}

// The columns that need no FE: the DEM's moduli, Amadei's with the DEM-measured and with Goodman's constants, the
// rock of the layers, the interfaces and Goodman's homogenized modulus of the same structure.
void theory_columns(ElasticReport& rep, const std::vector<DemJob>& jobs,
                    const std::vector<JointInterfaces>& interfaces, const Scene& scene, bool same_mesh_rock) {
  const BedSequence beds = bed_sequence(scene);
  rep.angles.resize(interfaces.size());
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    ElasticAngle& a = rep.angles[k];
    const DemJob& job = jobs[k];
    a.beta_deg = job.beta_deg;
    a.test = job.test;
    a.dem_static = job.test.platen_modulus;
    a.dem_gauge = job.test.gauge_modulus;
    a.amadei = theory::apparent_modulus(rep.dem.constants, a.beta_deg, rep.plane);
    a.amadei_goodman = theory::apparent_modulus(rep.goodman.constants, a.beta_deg, rep.plane);
    a.rock_test = job.rock_test;
    a.rock_constants = same_mesh_rock ? isotropic_constants(job.rock_test, rep.plane) : rep.intact_constants;
    a.rock2_test = job.rock2_test;
    a.rock2_constants = !rep.two_rocks ? a.rock_constants
                        : same_mesh_rock ? isotropic_constants(job.rock2_test, rep.plane)
                                         : rep.intact2_constants;
    a.interface_edges = interfaces[k].edges.size();
    a.glued_edges = interfaces[k].glued;
    a.stiffened_edges = interfaces[k].stiffened;
    // Goodman with the intact rock and this dip's interfaces: the homogenized modulus of the same structure.
    // Beds of two rocks: Salamon's medium, with the intact rocks (homogenized) and the rocks of the layers.
    const bool joints = scene.joint_set.enabled && !interfaces[k].edges.empty();
    if (joints && !rep.two_rocks)
      a.homogenized = theory::apparent_modulus(
          theory::goodman(rep.intact_constants.E, rep.intact_constants.nu, interfaces[k].mean_k_n(),
                          interfaces[k].mean_k_s(), scene.joint_set.spacing),
          a.beta_deg, rep.plane);
    if (joints && !beds.empty() && rep.two_rocks) {
      a.homogenized = interbedded_modulus(rep.intact_constants, rep.intact2_constants, beds, interfaces[k], scene,
                                          a.beta_deg, rep.plane);
      a.interbedded = interbedded_modulus(a.rock_constants, a.rock2_constants, beds, interfaces[k], scene,
                                          a.beta_deg, rep.plane);
    }
  }
}

#ifdef RBDEM_HAVE_CONTINUUM
// The homogenized FE models on one dip's mesh: the DEM-measured constants (dem_ok; with fields, the displacements
// beside the DEM's) and Goodman's (goodman_ok).
void homogenized_fe(ElasticAngle& a, const DemJob& job, const ElasticReport& rep, const Scene& scene,
                    const ElasticGateOptions& options, bool dem_ok, bool goodman_ok) {
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
      f.x = job.topo.blocks.cx, f.y = job.topo.blocks.cy, f.dem_ux = job.ux, f.dem_uy = job.uy;
      f.fe_ux = fe.ux, f.fe_uy = fe.uy;
      a.field_l2 = relative_l2(f.dem_ux, f.dem_uy, f.fe_ux, f.fe_uy, job.topo.blocks.area);
    }
  }
  if (goodman_ok) {
    fo.fields = false;
    a.fe_goodman = continuum::solve_elastic(job.mesh, rep.goodman.constants, a.beta_deg,
                                            scene.specimen.thickness, fo)
                       .apparent_modulus;
  }
  a.fe_seconds = seconds_since(t);
}

// The FE model with the joints on one dip's mesh: the rock of the layers (unilateral joints, the gauge and, with
// fields, the displacements), and the intact rock for the homogenization measure.
void jointed_fe(ElasticAngle& a, const DemJob& job, const JointInterfaces& interfaces, const ElasticReport& rep,
                const ElasticGateOptions& options, bool dem_ok) {
  const auto tj = Clock::now();
  if (a.rock_constants.admissible() && a.rock2_constants.admissible()) {
    const JointsSolve fj = solve_joints(job, a.rock_constants, a.rock2_constants, interfaces, rep.plane, options,
                                        true, options.joints_refinement, true);
    a.fe_joints_open_edges = fj.open_edges, a.fe_joints_state_solves = fj.state_solves;
    a.fe_joints_states_settled = fj.states_settled;
    a.fe_joints = fj.gauge_modulus, a.fe_joints_platen = fj.platen_modulus;
    a.fe_joints_gauge = fj.gauge, a.fe_joints_dofs = fj.dofs;
    if (options.fields) {
      AngleFields& f = a.fields;
      if (f.x.empty()) f.x = job.topo.blocks.cx, f.y = job.topo.blocks.cy;
      if (f.dem_ux.empty()) f.dem_ux = job.ux, f.dem_uy = job.uy;
      std::vector<double> dem_ux = job.ux;
      f.fe_joints_ux = fj.ux, f.fe_joints_uy = fj.uy;
      a.field_l2_joints = relative_l2(dem_ux, job.uy, f.fe_joints_ux, f.fe_joints_uy, job.topo.blocks.area);
      if (!dem_ok) f.dem_ux = std::move(dem_ux);  // the mean u_x removed, as relative_l2 does for the FE
    }
  }
  const theory::TIConstants& intact2 = rep.two_rocks ? rep.intact2_constants : rep.intact_constants;
  if (rep.intact_constants.admissible() && intact2.admissible() && std::isfinite(a.homogenized))
    a.fe_joints_intact_platen =
        solve_joints(job, rep.intact_constants, intact2, interfaces, rep.plane, options, false, 0, false)
            .platen_modulus;
  a.fe_joints_seconds = seconds_since(tj);
}

// Stage 3: the FE models on the same meshes, the dips side by side: homogenized (DEM constants, Goodman's) and with
// the joints.
void fe_stage(ElasticReport& rep, const std::vector<DemJob>& jobs, const std::vector<JointInterfaces>& interfaces,
              const Scene& scene, const ElasticGateOptions& options, int threads, SerialLog& log) {
  rep.fe_available = true;
  const auto t_fe = Clock::now();
  const bool dem_ok = rep.dem.admissible, goodman_ok = rep.goodman.constants.admissible();
  parallel_map(rep.angles.size(), threads, [&](std::size_t k) {
    ElasticAngle& a = rep.angles[k];
    homogenized_fe(a, jobs[k], rep, scene, options, dem_ok, goodman_ok);
    jointed_fe(a, jobs[k], interfaces[k], rep, options, dem_ok);
    log(fmt::format("  FE with joints beta {:g}: {} DoFs, {} interfaces ({} glued, {} open after {} solves{}; the "
                    "DEM opens {}), E_gauge {:.2f} GPa, {:.2f} s",
                    a.beta_deg, a.fe_joints_dofs, a.interface_edges, a.glued_edges, a.fe_joints_open_edges,
                    a.fe_joints_state_solves, a.fe_joints_states_settled ? "" : ", not settled",
                    a.test.open_joint_bonds, a.fe_joints / 1e9, a.fe_joints_seconds));
  });
  rep.fe_seconds = seconds_since(t_fe);
  for (const auto& a : rep.angles) rep.fe_joints_seconds += a.fe_joints_seconds;
}
#endif

// Goodman's homogenized medium (docs/theory.md) is one rock with one set of through-going joints. With two sets
// the compliances of both add and the medium is no longer transversely isotropic (the five-parameter theory does
// not hold); rock bridges and a second rock are outside it too. The FE model with the joints carries all three.
// Returns what of the scene is outside it (empty when nothing is).
std::string outside_goodman(const Scene& scene) {
  std::vector<std::string> outside;
  if (scene.joint_set2.enabled) outside.push_back("two joint sets (their compliances add; the medium is not TI)");
  if ((scene.joint_set.enabled && scene.joint_set.persistence < 1.0) ||
      (scene.joint_set2.enabled && scene.joint_set2.persistence < 1.0))
    outside.push_back("joints with rock bridges (persistence < 1)");
  if (!scene.rock2.groups.empty()) outside.push_back("layers of a second rock named by rock2.groups");
  if (!bed_sequence(scene).empty())
    outside.push_back("beds of two rocks (Salamon's interbedded medium is the homog and interbedded columns)");
  if (outside.empty()) return {};
  return fmt::format("Goodman's one-set medium does not model {}", fmt::join(outside, ", "));
}

// Homogenization: the indicator and, with the FE, its measured counterpart.
void homogenization(ElasticReport& rep, const std::vector<DemJob>& jobs, const Scene& scene) {
  Homogenization& h = rep.homogenization;
  const double s = scene.joint_set.spacing;
  const bool jointed = scene.joint_set.enabled && rep.interfaces.edges > 0;
  for (std::size_t k = 0; k + 1 < jobs.size(); ++k)
    h.joints_held = std::max(h.joints_held, jobs[k].mesh.num_layers() > 0 ? jobs[k].mesh.num_layers() - 1 : 0);
  h.layers_across = jointed ? rep.width / s : std::numeric_limits<double>::infinity();
  h.contrast = scene.rock.effective_modulus / scene.joint.effective_modulus;
  h.compliance_ratio = jointed ? rep.goodman.E_r / (rep.interfaces.k_n * s) : 0.0;  // 0 when glued (k_n = inf)
  h.indicator = jointed ? h.compliance_ratio / h.layers_across : 0.0;
  h.max_indicator = homogenization_max_indicator;
  h.applies = h.indicator <= h.max_indicator;
  h.outside = outside_goodman(scene);
  if (!h.outside.empty()) h.applies = false;
  if (rep.fe_available && jointed) {
    double worst = 0;
    for (const auto& a : rep.angles) worst = worse(worst, a.homogenization_error());
    h.measured_error = worst;
  } else if (!jointed) {
    h.measured_error = 0;
  }
}

// Amadei beside the verdict: a fair comparison when homogenization applies and the DEM is one TI continuum.
void amadei_check(ElasticReport& rep, GateMeasure measure) {
  AmadeiCheck& am = rep.amadei;
  for (const auto& a : rep.angles) track(am.max_deviation, am.worst_beta_deg, a.deviation(measure), a.beta_deg);
  const Homogenization& h = rep.homogenization;
  const bool ti = rep.dem.admissible && rep.dem.residual <= am.max_residual_for_ti;
  am.applicable = h.applies && ti;
  std::vector<std::string> why;
  if (!h.outside.empty())
    why.push_back(h.outside);
  else if (!h.applies)
    why.push_back(fmt::format("layers do not homogenize ({:.3g} layers across, joint compliance {:.3g} x the "
                              "rock's over one spacing, contrast E*_r/E*_j {:.3g}: indicator {:.3g} > {:.3g})",
                              h.layers_across, h.compliance_ratio, h.contrast, h.indicator, h.max_indicator));
  if (!rep.dem.admissible)
    why.push_back("the DEM-measured constants are not admissible (the compliance is not positive definite)");
  else if (!ti)
    why.push_back(fmt::format("the DEM is not one TI continuum (fit residual {:.2f} % > {:.2f} %)",
                              100.0 * rep.dem.residual, 100.0 * am.max_residual_for_ti));
  if (am.applicable)
    am.note = fmt::format("homogenization applies: {:.3g} layers across, joint compliance {:.3g} x the rock's over "
                          "one spacing, contrast E*_r/E*_j {:.3g}, fit residual {:.2f} %",
                          h.layers_across, h.compliance_ratio, h.contrast, 100.0 * rep.dem.residual);
  else
    am.note = fmt::format("{}", fmt::join(why, " and "));
}

// The DEM against the FE model with the joints ("fe_joints"): the maxima of both measures, and "passed" within the
// tolerance. Returns the gated measure's maximum, before a linear check may decide.
double joints_comparison(ElasticReport& rep, const std::string& amadei_text) {
  GateVerdict& g = rep.gate;
  g.comparison = "fe_joints";
  double platen = 0, gauge = 0;
  for (const auto& a : rep.angles) {
    track(g.max_deviation, g.worst_beta_deg, a.deviation_joints(g.measure), a.beta_deg);
    platen = worse(platen, a.deviation_joints(GateMeasure::platen));
    gauge = worse(gauge, a.deviation_joints(GateMeasure::gauge));
  }
  g.max_deviation_joints = gauge, g.max_deviation_joints_platen = platen;
  g.worst_beta_joints_deg = g.worst_beta_deg;
  const double missed = g.max_deviation;  // of the gated measure, before a linear check may decide
  g.passed = g.max_deviation <= g.tolerance;
  if (g.passed)
    g.message = fmt::format("passed: DEM within {:.2f} % of the FE model with the joints as interfaces (the "
                            "comparison that always applies; worst at beta = {:g} deg, tolerance {:.2f} %); {}",
                            100.0 * g.max_deviation, g.worst_beta_deg, 100.0 * g.tolerance, amadei_text);
  return missed;
}

// Why the DEM missed the FE model with the joints and what to do, with what the linear check (if run) found.
void joints_failure(ElasticReport& rep, double missed, double end_fraction, const std::string& amadei_text) {
  GateVerdict& g = rep.gate;
  std::string linear_text;
  if (rep.linear_check_run)
    linear_text = fmt::format(
        "; with every linear part closed and sticking the DEM is {:.2f} % off the same model ({})",
        100.0 * g.max_deviation_linear,
        g.max_deviation_linear > g.tolerance ? "so opening linear parts do not explain it"
        : rep.linear_check_sliding
            ? "but linear parts slide at the dips that miss: Coulomb sliding, not opening, softens the DEM there; "
              "raise joint.contact_friction / rock.contact_friction if the joints should stick"
            : "but the DEM as it runs is stiffer than its linear self where it misses, which opening cannot "
              "explain");
  g.reason = fmt::format(
      "|{} / fe_joints - 1| = {:.2f} % at beta = {:g} deg exceeds the tolerance {:.2f} %: the DEM does not "
      "reproduce the FE model with the joints as interfaces (layers of the rock measured on the same mesh; the "
      "comparison that always applies){}. At the worst dip: sliding linear parts (sliding_linear_parts in "
      "elastic.json) point at the friction (raise joint.contact_friction or set joint.slip_when_bonded = false "
      "if the joints should stick); a difference growing from 45 to 75 deg points at too few blocks across a "
      "bending layer (about 7 are needed; docs/elastic.md) or joints in the gauge's end zones (the outer {:.0f} % "
      "of H): refine mesh.size",
      measure_name(g.measure), 100.0 * missed, g.worst_beta_deg, 100.0 * g.tolerance, linear_text,
      100.0 * end_fraction);
  g.message = fmt::format("FAILED: DEM {:.2f} % off the FE model with the joints as interfaces at beta = {:g} deg "
                          "(tolerance {:.2f} %){}; {}",
                          100.0 * missed, g.worst_beta_deg, 100.0 * g.tolerance, linear_text, amadei_text);
}

// The message when the linear check decided (linear_check() set passed and the numbers): the DEM as it runs misses
// only through linear parts opening in tension.
void linear_check_message(ElasticReport& rep, const std::string& amadei_text) {
  GateVerdict& g = rep.gate;
  std::size_t open = 0, bonds = 0, rock_open = 0, joint_open = 0, fe_open = 0;
  for (const auto& a : rep.angles)
    if (a.beta_deg == g.worst_beta_joints_deg)
      open = a.test.open_bonds, bonds = a.test.bonds, rock_open = a.rock_test.open_bonds,
      joint_open = a.test.open_joint_bonds, fe_open = a.fe_joints_open_edges;
  g.reason.clear();
  g.message = fmt::format(
      "passed: DEM with every linear part closed within {:.2f} % of the FE model with the joints as interfaces "
      "(worst at beta = {:g} deg, tolerance {:.2f} %); the DEM as it runs is up to {:.2f} % softer (beta = {:g} "
      "deg) because its linear parts open in tension ({} of {} bonds open there, {} in the same mesh with rock "
      "joints): {} joint bonds, which the FE model's unilateral joints open too ({} edges), and {} rock bonds "
      "in the bending layers, which its elastic layers cannot represent; {}",
      100.0 * g.max_deviation, g.worst_beta_deg, 100.0 * g.tolerance, 100.0 * g.max_deviation_joints,
      g.worst_beta_joints_deg, open, bonds, rock_open, joint_open, fe_open, open - joint_open, amadei_text);
}

// No FE model with the joints (a build without deal.II, or a rock of the layers that is not admissible): Amadei
// decides, as the only comparison there is.
void amadei_verdict(ElasticReport& rep) {
  GateVerdict& g = rep.gate;
  const AmadeiCheck& am = rep.amadei;
  g.comparison = "amadei";
  g.max_deviation = am.max_deviation, g.worst_beta_deg = am.worst_beta_deg;
  g.passed = rep.dem.admissible && g.max_deviation <= g.tolerance;
  const std::string why = rep.fe_available ? "the rock of the layers is not an admissible material, so the FE "
                                             "model with the joints could not run"
                                           : "this build has no deal.II, so the FE model with the joints does not "
                                             "exist";
  if (!rep.dem.admissible)
    g.reason = "the DEM-measured constants are not admissible (the compliance is not positive definite): the DEM "
               "specimen does not behave as a transversely isotropic continuum; Amadei decides because " + why;
  else if (!g.passed)
    g.reason = fmt::format("|{} / amadei - 1| = {:.2f} % at beta = {:g} deg exceeds the tolerance {:.2f} % "
                           "(Amadei decides because {}; {}). When layers do not homogenize this is expected: run "
                           "the gate in a deal.II build, where the FE model with the joints decides",
                           measure_name(g.measure), 100.0 * g.max_deviation, g.worst_beta_deg,
                           100.0 * g.tolerance, why, am.note);
  g.message = fmt::format("{}: DEM {:.2f} % off Amadei with its own constants at beta = {:g} deg (the comparison "
                          "that decides because {}; {})",
                          g.passed ? "passed" : "FAILED", 100.0 * g.max_deviation, g.worst_beta_deg, why,
                          am.applicable ? am.note : "Amadei is not a fair reference here: " + am.note);
}

// The verdict: the DEM against the FE model with the joints (Amadei when the build has no deal.II).
void verdict(ElasticReport& rep, [[maybe_unused]] const std::vector<DemJob>& jobs,
             [[maybe_unused]] const std::vector<JointInterfaces>& interfaces, [[maybe_unused]] const Scene& scene,
             const ElasticGateOptions& options, [[maybe_unused]] int threads) {
  GateVerdict& g = rep.gate;
  for (const auto& a : rep.angles) {
    g.max_deviation_static = std::max(g.max_deviation_static, std::abs(a.deviation(GateMeasure::platen)));
    g.max_deviation_gauge = std::max(g.max_deviation_gauge, std::abs(a.deviation(GateMeasure::gauge)));
  }
  const AmadeiCheck& am = rep.amadei;
  const std::string amadei_text =
      am.applicable ? fmt::format("Amadei {:.2f} % ({})", 100.0 * am.max_deviation, am.note)
                    : fmt::format("Amadei not applicable: {:.2f} % off because {}", 100.0 * am.max_deviation, am.note);
  bool joints_model = rep.fe_available;
  for (const auto& a : rep.angles) joints_model = joints_model && std::isfinite(a.fe_joints);
  if (!joints_model) {
    amadei_verdict(rep);
    return;
  }
  const double missed = joints_comparison(rep, amadei_text);
#ifdef RBDEM_HAVE_CONTINUUM
  if (!g.passed && options.linear_check) linear_check(rep, jobs, interfaces, scene, options, threads);
#endif
  if (!g.passed) joints_failure(rep, missed, options.end_fraction, amadei_text);
  if (g.comparison == "fe_joints_linear") linear_check_message(rep, amadei_text);
}

}  // namespace

const char* measure_name(GateMeasure m) { return m == GateMeasure::gauge ? "dem_gauge" : "dem_static"; }

ElasticReport run_elastic_gate(const Scene& scene_in, const ElasticGateOptions& options) {
  const auto t0 = Clock::now();
  check_gate_inputs(scene_in, options);
  const Scene scene = elastic_test_scene(scene_in);
  const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  SerialLog log(options.log);
#ifdef RBDEM_HAVE_CONTINUUM
  const bool with_fe = options.with_fe;
#else
  const bool with_fe = false;
#endif
  const bool same_mesh_rock = with_fe && options.layer_rock == ElasticGateOptions::LayerRock::same_mesh;

  ElasticReport rep;
  rep.plane = theory::plane_from_string(scene.specimen.model);
  rep.mesh_size = scene.mesh.size;
  rep.gate.tolerance = scene.elastic.tolerance;
  rep.gate.measure = options.measure;

  const auto t_dem = Clock::now();
  const std::vector<DemJob> jobs = measure_dips(scene, options, same_mesh_rock, threads, log);
  rep.dem_seconds = seconds_since(t_dem);
  rep.width = jobs.back().topo.width(), rep.height = jobs.back().topo.height();

  fit_constants(rep, jobs, scene, options);
  const std::vector<JointInterfaces> interfaces = dip_interfaces(rep, jobs, scene);
  theory_columns(rep, jobs, interfaces, scene, same_mesh_rock);
#ifdef RBDEM_HAVE_CONTINUUM
  if (with_fe) fe_stage(rep, jobs, interfaces, scene, options, threads, log);
#endif
  homogenization(rep, jobs, scene);
  amadei_check(rep, options.measure);
  verdict(rep, jobs, interfaces, scene, options, threads);
  rep.seconds = seconds_since(t0);
  return rep;
}

}  // namespace rbdem::compare
