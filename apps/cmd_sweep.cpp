// rbdem sweep: a parameter study (dips x scene variations), and the main job (the default dip study).
//
//   rbdem sweep scenes/study_joint_strength.toml --out runs/strength     # all cores
//   mpirun -np 4 rbdem sweep scenes/study_spacing.toml --out runs/spacing # cases spread over the ranks
//   rbdem                                                                 # the paper's dip study, report
// Each case gets its own folder; table.csv, groups.csv, timing.csv and report.md summarise the study. A sweep
// stopped with Ctrl-C (or killed) resumes where it stopped when rerun with the same command. Before any case runs,
// every case's scene is checked as `rbdem ucs` checks one (a strength at or above its modulus is refused unless
// --force) and its cost estimated (refused when the cases run at once exceed the available memory).
#include <mpi.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/gate/gate_cache.hpp"
#include "dem/driver/registry.hpp"
#include "theory/elasticity.hpp"
#include "io/results.hpp"
#include "study/report.hpp"
#include "study/study.hpp"

namespace rbdem::cli {

namespace {

std::atomic<bool> interrupted{false};
volatile std::sig_atomic_t last_signal = 0;
extern "C" void on_sigint(int sig) {
  last_signal = sig;
  interrupted.store(true);
}

struct SweepOptions {
  std::string study;
  std::string out = "runs/sweep";
  std::vector<std::string> sets;
  int workers = 0;
  bool quiet = false;
  bool skip_elastic_gate = false;
  bool force = false;
  int realizations = 0;  // 0: the study's own
};

// MPI only when launched by mpirun (OpenMPI, MPICH/PMI): a plain run needs no MPI at all.
struct MpiSession {
  int rank = 0, size = 1;
  bool active = false;
  MpiSession() {
    const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE");
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!launched && !initialised) return;
    if (!initialised) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      owner = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    active = true;
  }
  ~MpiSession() {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (owner && !finalised) MPI_Finalize();
  }
  void barrier() const {
    if (active) MPI_Barrier(MPI_COMM_WORLD);
  }
  bool owner = false;
};

// Every case's scene, before any runs: the likely unit mistakes of check_plausible (unless --force), named by case,
// and the memory of the cases that run at once in this process.
void check_cases(const std::vector<study::Case>& cases, int concurrent, bool force, bool quiet) {
  const study::Case* costliest = nullptr;
  for (const auto& c : cases) {
    try {
      if (!force) check_plausible(c.scene);
    } catch (const SceneError& e) {
      throw SceneError(fmt::format("case {}: {}", c.id, e.what()));
    }
    if (c.scene.mesh.file.empty() &&
        (!costliest || estimate_cost(c.scene).bytes > estimate_cost(costliest->scene).bytes))
      costliest = &c;
  }
  if (!costliest) return;
  try {
    check_cost(costliest->scene, "sweep", std::min<int>(concurrent, int(cases.size())), force, quiet);
  } catch (const SceneError& e) {
    throw SceneError(fmt::format("case {}: {}", costliest->id, e.what()));
  }
}

int run_study(study::StudySpec spec, const std::filesystem::path& out, int workers, bool quiet, bool paper_check,
              bool skip_gate, bool force) {
  io::require_writable_dir(out);  // before the gate and any case: a clear error naming the folder, exit 2
  MpiSession mpi;
  const auto t0 = std::chrono::steady_clock::now();
  const auto cases = study::expand(spec);
  // The cases share the cores, `workers` of them (all by default); the last ones get more as others finish
  // (study::run_cases).
  const int concurrent = workers > 0 ? workers : (mpi.size > 1 ? 1 : int(std::max(1u, std::thread::hardware_concurrency())));
  check_cases(cases, concurrent, force, quiet || mpi.rank != 0);
  // The elastic gate, once per distinct elastic scene (groups varying e.g. kn/ks differ; verdicts are cached).
  std::string gate_markdown;
  if (!skip_gate) {
    std::set<std::string> seen;
    for (const auto& c : cases) {
      if (c.realization > 0) continue;  // the first mesh of a case stands for its realizations
      // Once per elastic behaviour: the gate's own key leaves out what it does not depend on (the dip, which it
      // sweeps itself, the strengths, sigma_3), so a dip study checks once, not once per dip.
      if (!seen.insert(compare::elastic_gate_key(gate_scene(c.scene))).second) continue;
      const compare::GateCheck g = compare::check_elastic_gate(gate_scene(c.scene));
      if (g.status == compare::GateCheck::Status::failed) {
        if (mpi.rank == 0)
          fmt::print(stderr, "{}\nsweep: the elastic gate failed for {} ({}); the DEM does not behave as the "
                             "transversely isotropic material it should before failure runs make sense. Fix the scene "
                             "(a finer mesh.size usually), or run anyway with --skip-elastic-gate\n",
                     g.table, c.group.empty() ? "the base scene" : c.group, g.summary);
        return check_failed;
      }
      if (mpi.rank == 0) fmt::print("{}{}\n", g.summary, c.group.empty() ? "" : " [" + c.group + "]");
      if (g.status == compare::GateCheck::Status::passed)
        gate_markdown += (c.group.empty() ? "" : "**" + c.group + "**\n\n") + "```\n" + g.table + "```\n\n";
    }
  }
  const bool tty = isatty(fileno(stderr)) && !quiet;
  if (mpi.rank == 0)
    fmt::print("sweep {}: {} cases ({} dips{}{}) into {}{}\n", spec.name, cases.size(), spec.dips.size(),
               spec.axes.empty() ? ""
                                 : fmt::format(" x {} variations", cases.size() / spec.dips.size() / spec.realizations),
               spec.realizations > 1 ? fmt::format(" x {} realizations", spec.realizations) : "", out.string(),
               mpi.size > 1 ? fmt::format(" over {} MPI ranks", mpi.size) : "");
  study::SweepOptions ro;
  ro.workers = workers > 0 ? workers : (mpi.size > 1 ? 1 : 0);
  ro.progress = tty;
  ro.cancel = &interrupted;
  // Not on a terminal (a log, a batch job): a plain line on stdout as each case finishes, on every rank.
  std::size_t finished = 0;
  const std::string of_total =
      mpi.size > 1 ? fmt::format(" on rank {}", mpi.rank)
                   : fmt::format(" of {} to run", cases.size() - study::collect(cases, out).size());
  if (!isatty(fileno(stdout)) && !quiet)
    ro.on_done = [&](const study::CaseResult& r) {
      ++finished;
      fmt::print("sweep: case {} done ({}{}): peak {:.2f} MPa, {}, {}\n", r.c.id, finished, of_total,
                 r.summary.value("peak_stress_pa", 0.0) / 1e6, r.summary.value("failure_mode", std::string("?")),
                 duration_text(r.wall_seconds));
      std::fflush(stdout);
    };
  auto previous = std::signal(SIGINT, on_sigint);
  auto previous_term = std::signal(SIGTERM, on_sigint);
  std::vector<study::CaseResult> ran;
  try {
    ran = study::run_cases(cases, out, ro, mpi.rank, mpi.size);
  } catch (const study::Cancelled&) {
    std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
    const auto done = study::collect(cases, out).size();
    fmt::print(stderr, "sweep: interrupted with {} of {} cases complete; rerun the same command to finish\n", done,
               cases.size());
    return last_signal == SIGTERM ? 143 : 130;
  } catch (...) {
    std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
    throw;
  }
  std::signal(SIGINT, previous), std::signal(SIGTERM, previous_term);
  mpi.barrier();
  if (mpi.rank != 0) return ok;
  // Everything from disk (other ranks' cases too), with this process's timings where it ran the case.
  auto results = study::collect(cases, out);
  for (auto& r : results)
    for (const auto& mine : ran)
      if (mine.c.id == r.c.id) r.reused = mine.reused, r.wall_seconds = mine.wall_seconds;
  if (results.size() != cases.size())
    throw std::runtime_error(fmt::format("sweep: {} of {} cases have no summary.json in {}", cases.size() - results.size(),
                                         cases.size(), out.string()));
  const auto groups = study::write_tables(results, out);
  study::write_timing(results, out);
  // The report and the printed table show one row per case: the mean over its realizations (the case itself
  // without realizations).
  const auto points = study::realization_means(results);
  std::vector<study::CaseResult> rows;
  for (const auto& p : points) rows.push_back(p.mean);
  study::ReportExtras extras;
  const ProtocolInfo& test = protocol_info(spec.test);
  if (test.confined) extras.envelopes = study::write_envelopes(results, out);
  extras.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  extras.workers = ro.workers > 0 ? ro.workers : int(std::thread::hardware_concurrency());
  extras.paper_check = paper_check;
  extras.elastic_gate_markdown = gate_markdown;
  if (spec.realizations > 1) extras.points = &points;
  const auto report = study::write_report(spec, rows, groups, out, extras);

  std::map<std::string, double> s90;
  for (const auto& g : groups) s90[g.group] = g.strength_90_pa;
  if (test.tensile) {
    fmt::print("\n{:<34} {:>6} {:>12} {:>12} {:>12}  {}\n", "case", "beta", "layers/load", "tensile MPa", "load kN",
               "failure mode");
    for (const auto& r : rows) {
      const auto& s = r.summary;
      fmt::print("{:<34} {:>6g} {:>12g} {:>12.3f} {:>12.2f}  {}\n", r.c.id, r.c.beta,
                 s.value("layer_angle_deg", 0.0), s.value("tensile_strength_pa", 0.0) / 1e6,
                 s.value("peak_load_n", 0.0) / 1e3, s["failure_mode"].get<std::string>());
    }
  } else {
    const bool spread = spec.realizations > 1;
    fmt::print("\n{:<34} {:>6} {:>10}{} {:>10} {:>10}  {}\n", "case", "beta", spread ? "mean MPa" : "peak MPa",
               spread ? fmt::format(" {:>8} {:>10}", "sd MPa", "95 % +-") : "", "Jaeger MPa", "E50 GPa",
               "failure mode");
    for (const auto& p : points) {
      const auto& r = p.mean;
      const auto& s = r.summary;
      const double jaeger = study::jaeger_for(r.c.scene, r.c.beta, s90[r.c.group]);
      fmt::print("{:<34} {:>6g} {:>10.2f}{} {:>10} {:>10.1f}  {}\n", spread ? r.c.point : r.c.id, r.c.beta,
                 s["peak_stress_pa"].get<double>() / 1e6,
                 spread ? fmt::format(" {:>8.2f} {:>10.2f}", p.peak.sd / 1e6, p.peak.ci95 / 1e6) : "",
                 std::isfinite(jaeger) ? fmt::format("{:.2f}", jaeger / 1e6) : "n/a",
                 s["youngs_modulus_pa"].get<double>() / 1e9, s["failure_mode"].get<std::string>());
    }
    for (const auto& g : groups)
      fmt::print("{}minimum {:.2f} MPa at {:g} deg ({}), {}\n", g.group.empty() ? "" : "group " + g.group + ": ",
                 g.min_strength_pa / 1e6, g.min_beta_deg,
                 std::isfinite(g.jaeger_min_pa)
                     ? fmt::format("Jaeger {:.2f} MPa at {:.0f} deg", g.jaeger_min_pa / 1e6, g.jaeger_min_beta_deg)
                     : std::string("Jaeger n/a: no 0 or 90 deg case for the intact strength"),
                 std::isfinite(g.anisotropy_ratio)
                     ? fmt::format("anisotropy ratio {:.2f} (intact / minimum)", g.anisotropy_ratio)
                     : std::string("anisotropy ratio n/a"));
    for (const auto& e : extras.envelopes)
      fmt::print("envelope at {:g} deg: sigma_1 = {:.2f} MPa + {:.3f} sigma_3 (phi {:.1f} deg, c {:.2f} MPa){}\n",
                 e.beta_deg, e.intercept_pa / 1e6, e.slope, e.friction_deg, e.cohesion_pa / 1e6,
                 e.slip_range ? fmt::format("; Jaeger's slope for sliding {:.3f}, measured 0-10 MPa {:.3f}{}",
                                            e.jaeger_slope, e.slope_0_10,
                                            std::isfinite(e.slope_0_10_se)
                                                ? fmt::format(" +- {:.3f} (standard error)", e.slope_0_10_se)
                                                : std::string())
                              : std::string());
  }
  fmt::print("sweep: {:.1f} s wall; table {}, report {}\n", extras.wall_seconds, (out / "table.csv").string(),
             report.string());
  return ok;
}

}  // namespace

Runner add_sweep_command(CLI::App& app) {
  auto opt = std::make_shared<SweepOptions>();
  CLI::App* cmd = app.add_subcommand("sweep", "a parameter study: one folder per case, table.csv, report.md");
  cmd->add_option("study", opt->study, "study file (TOML with a [study] table; see scenes/study_*.toml)")->required();
  cmd->add_option("--out,-o", opt->out, "output folder (rerun to resume)")->capture_default_str();
  cmd->add_option("--set", opt->sets, "override a key of the study's base scene, e.g. --set mesh.size=0.002")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cmd->add_option("--workers,-j", opt->workers, "cases run at once in this process (default: all cores)");
  cmd->add_flag("--quiet,-q", opt->quiet, "no progress lines");
  cmd->add_flag("--skip-elastic-gate", opt->skip_elastic_gate,
                "run even when the elastic gate fails (DEM vs the FE model with the joints, and Amadei where the layers homogenize; rbdem elastic)");
  cmd->add_option("--realizations", opt->realizations,
                  "meshes per case (mesh.seed = base seed + 0 .. N-1), instead of the study's realizations")
      ->type_name("N");
  add_force_flag(*cmd, opt->force);
  return [opt, cmd]() {
    study::StudySpec spec =
        load_input(opt->study, InputKind::study, [](const auto& f) { return study::load_study(f); });
    for (const auto& s : opt->sets) apply_override(spec.base, s);
    validate(spec.base);
    if (cmd->count("--realizations")) spec.realizations = opt->realizations;
    study::check_realizations(spec.realizations, spec.base);
    return run_study(spec, opt->out, opt->workers, opt->quiet, false, opt->skip_elastic_gate, opt->force);
  };
}

int run_default_job(int realizations) {
  const Scene scene;
  study::check_realizations(realizations, scene);
  study::StudySpec spec = study::dip_study(scene, "paper_dips");
  spec.description = "The seed paper's uniaxial compression study: the 100 x 50 mm specimen with joints every 10 mm "
                     "at dips 0 to 90 deg (the built-in paper scene, the same values as scenes/paper.toml).";
  spec.realizations = realizations;
  if (realizations > 1)
    spec.description += fmt::format(" {} meshes per dip (mesh.seed 0 to {}): the mean peak with its 95 % interval.",
                                    realizations, realizations - 1);
  fmt::print("rbdem: the default study on {} (rbdem --help lists the commands)\n", builtin_scene);
  return run_study(spec, realizations > 1 ? "runs/default_realizations" : "runs/default", 0, false, true, false,
                   false);
}

}  // namespace rbdem::cli
