// Parameter studies: many cases of one test (uniaxial, confined or Brazilian; dips x parameter variations), run on all
// cores or over MPI ranks, resumable, summarised in one table with Jaeger's plane-of-weakness strength beside the
// measured one (and, for confined studies, the strength envelope of each dip: envelope.csv).
//
// A study file (TOML) names a base scene, fixed overrides, the dips, and axes of variation; each axis gives one
// label per case and, per varied key, either the values or factors of another key of the base scene:
//
//   [study]
//   name = "joint_strength"
//   test = "ucs"                              # ucs (default) | triaxial | brazilian
//   base = "paper.toml"                       # relative to the study file; empty = built-in defaults
//   dips = [0, 15, 30, 45, 60, 75, 90]
//   realizations = 5                          # meshes per case: mesh.seed = base seed + 0, 1, ..., 4 (default 1)
//   [study.set]                               # overrides for every case
//   "mesh.size" = 0.001
//   [[axis]]
//   name = "strength_ratio"
//   labels = ["0.25", "0.5", "0.75", "1"]
//   [axis.set]
//   "joint.cohesion" = { of = "rock.cohesion", factors = [0.25, 0.5, 0.75, 1.0] }
//   "joint.tensile_strength" = [3e6, 6e6, 9e6, 12e6]
//
// Cases are the product of the axes, the dips and the realizations. Each case writes its own folder (summary.json
// last, so a folder with a summary.json is complete); a rerun skips complete cases and reruns interrupted ones.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dem/scene.hpp"
#include "dem/driver/driver.hpp"

namespace rbdem::study {

struct Axis {
  std::string name;
  std::vector<std::string> labels;
  // key -> one textual value per label (already resolved from factors)
  std::vector<std::pair<std::string, std::vector<std::string>>> values;
};

struct StudySpec {
  std::string name = "study";
  std::string test = "ucs";  // ucs | triaxial | brazilian
  std::string description;
  Scene base;
  std::vector<double> dips{0, 15, 30, 45, 60, 75, 90};
  std::vector<Axis> axes;
  int realizations = 1;          // meshes per group and dip (mesh.seed = base seed + 0 .. realizations - 1)
  std::filesystem::path source;  // the study file, for messages
};

// The largest study.realizations accepted.
inline constexpr int max_realizations = 1000;

struct Case {
  std::string test = "ucs";       // the test each case runs
  std::string id;                 // folder name, e.g. "strength_ratio=0.5/beta=60" (".../beta=60/seed=2" with
                                  // realizations)
  std::string group;              // the case without its dip, e.g. "strength_ratio=0.5" ("" without axes)
  std::string point;              // the case without its realization, e.g. "strength_ratio=0.5/beta=60"
  int realization = -1;           // 0 .. realizations - 1 in a study with realizations > 1; -1 otherwise
  std::vector<std::pair<std::string, std::string>> labels;  // axis name -> label
  double beta = 0;
  Scene scene;
};

// Reads a study file. Throws SceneError naming the file and the key for any problem.
StudySpec load_study(const std::filesystem::path& path);
// The study of the main job: the paper's dip study on a scene.
StudySpec dip_study(const Scene& base, std::string name = "dips");
// Refuses (SceneError naming the value and the fix) a count of realizations out of [1, max_realizations], and
// realizations of a user mesh, which cannot be re-meshed.
void check_realizations(int realizations, const Scene& base);
// All cases in a fixed order: axes outermost (in file order), then dips, realizations innermost.
std::vector<Case> expand(const StudySpec& spec);

struct CaseResult {
  Case c;
  nlohmann::json summary;   // the case's summary.json
  bool reused = false;      // found complete on disk
  double wall_seconds = 0;
};

struct SweepOptions {
  int workers = 0;                                  // concurrent cases in this process; 0 = all cores
  bool progress = false;                            // progress lines on stderr (terminals only)
  const std::atomic<bool>* cancel = nullptr;        // set to stop: running cases abort without a summary
  std::function<void(const CaseResult&)> on_done;   // called from worker threads, serialised
};

// Runs the cases not yet complete under `out`, in parallel; returns the results of all cases (complete ones read
// from disk). Under MPI (mpi_size > 1) each rank runs the cases with index % size == rank. Throws on a failed case
// after the others finished; a cancelled run throws study::Cancelled.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};
// The threads of each running case (in the order they started) when `cores` are shared by `holders` cases (the
// running ones, or while cases wait in the queue, one per worker): as evenly as the count allows, the cases that
// started first holding the cores left over; at least one each.
std::vector<int> share_cores(int cores, std::size_t holders, std::size_t running);

std::vector<CaseResult> run_cases(const std::vector<Case>& cases, const std::filesystem::path& out,
                                  const SweepOptions& options, int mpi_rank = 0, int mpi_size = 1);

// Reads the results of all cases from their folders (after an MPI run, on rank 0); missing ones are skipped.
std::vector<CaseResult> collect(const std::vector<Case>& cases, const std::filesystem::path& out);

// Jaeger's uniaxial strength for one case: sliding on the joint or, where sliding cannot govern, the group's
// measured strength at beta = 90. The joint's envelope is the bonded interface's (dem/contact_law.hpp,
// interface_envelope: the linear part shares the traction with the bond), or with `bond_values` the joint bonds'
// own cohesion and friction angle.
double jaeger_for(const Scene& scene, double beta, double strength_90, bool bond_values = false);

// Student's t quantile t_{0.975, dof}: the half-width of a two-sided 95 % interval of a mean is
// t_{0.975, n-1} sd / sqrt(n). Exact to 9 digits for dof <= 30 (tabulated), a Cornish-Fisher expansion above
// (within 1e-7). Throws std::invalid_argument for dof < 1.
double student_t975(int dof);

// The sample statistics of one quantity over the realizations of a case.
struct SampleStats {
  int n = 0;
  double mean = 0;
  double sd = 0;           // with n - 1 in the denominator; 0 for n = 1
  double ci95 = 0;         // half-width t_{0.975, n-1} sd / sqrt(n); NaN for n = 1
};
SampleStats sample_stats(const std::vector<double>& values);

// One row per case of a study with realizations: `mean.summary` holds the means of the numeric fields of the
// realizations' summaries (cracks too) and the most frequent failure mode and stop reason; `mean.c` is the first
// realization's case. The peak (and, for the Brazilian test, the tensile strength) with its spread.
struct PointResult {
  CaseResult mean;
  SampleStats peak;
  SampleStats tensile;     // n = 0 unless the cases report tensile_strength_pa
  std::vector<const CaseResult*> realizations;
};
// The means of the realizations of every case, in the order of the cases (results of a study without
// realizations give one row each, with n = 1).
std::vector<PointResult> realization_means(const std::vector<CaseResult>& results);

struct GroupSummary {
  std::string group;
  double min_strength_pa = 0, min_beta_deg = 0;          // measured
  double jaeger_min_pa = 0, jaeger_min_beta_deg = 0;     // Jaeger (intact strength = measured beta = 90)
  // Jaeger's intact strength (the group's beta = 90 deg case, else its 0 deg case; NaN without either) and the
  // anisotropy ratio it gives: intact over the least strength (NaN without an intact strength).
  double strength_90_pa = 0, anisotropy_ratio = 0;
};

// Writes table.csv (deterministic: no timings) and groups.csv, returns the group summaries. With realizations
// (cases with realization >= 0), table.csv holds one row per case with the means and the spread of the peak, the
// per-realization rows go to realizations.csv, and groups.csv and Jaeger use the means.
std::vector<GroupSummary> write_tables(const std::vector<CaseResult>& results, const std::filesystem::path& out);
// Writes timing.csv (wall seconds, steps per case).
void write_timing(const std::vector<CaseResult>& results, const std::filesystem::path& out);

// The strength envelope of each dip of a confined study: the least-squares line sigma_1 = sigma_c + k sigma_3 through
// the dip's cases, the friction angle phi = asin((k - 1)/(k + 1)) and cohesion c = sigma_c (1 - sin phi)/(2 cos phi)
// it implies, the slope between sigma_3 = 0 and 10 MPa where both were run, and Jaeger's slope for sliding on the
// joints, 1 + 2 mu / ((1 - mu cot beta) sin 2 beta) (infinite where sliding cannot govern).
struct Envelope {
  double beta_deg = 0;
  int points = 0;
  double slope = 0, intercept_pa = 0, friction_deg = 0, cohesion_pa = 0;
  double slope_0_10 = 0;           // NaN when sigma_3 = 0 or 10 MPa is missing; with realizations, of the means
  double slope_0_10_se = 0;        // its standard error from the scatter of the realizations; NaN with one mesh
  double jaeger_slope = 0;         // of sliding on the joints; +inf outside the slip range
  bool slip_range = false;         // Jaeger: sliding governs at this dip at sigma_3 = 0
};
// Writes envelope.csv and returns the envelopes (one per dip), for a study whose cases carry different
// loading.confining_pressure values.
std::vector<Envelope> write_envelopes(const std::vector<CaseResult>& results, const std::filesystem::path& out);

}  // namespace rbdem::study
