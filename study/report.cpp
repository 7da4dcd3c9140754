// Study report and figures. See report.hpp.
#include "study/report.hpp"

#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "dem/driver/registry.hpp"
#include "io/results.hpp"
#include "theory/elasticity.hpp"

#ifndef RBDEM_SOURCE_DIR
#define RBDEM_SOURCE_DIR ""
#endif
#ifndef RBDEM_INSTALL_DATADIR
#define RBDEM_INSTALL_DATADIR ""
#endif

namespace rbdem::study {

namespace {

std::string quote(const std::filesystem::path& p) {
  std::string s = "'";
  for (char c : p.string()) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return s + "'";
}

bool run(const std::string& command) { return std::system((command + " > /dev/null 2>&1").c_str()) == 0; }

}  // namespace

std::string figure_python() {
  // Looked up once: each probe starts a Python that imports matplotlib (a second or so).
  static const std::string python = [] {
    if (const char* env = std::getenv("RBDEM_PYTHON"); env && *env) return std::string(env);
    if (run("python3 -c 'import matplotlib, h5py, numpy'")) return std::string("python3");
    return std::string("/usr/bin/python3");
  }();
  return python;
}

std::filesystem::path figure_script() {
  std::vector<std::filesystem::path> candidates;
  if (const char* env = std::getenv("RBDEM_PYTHON_DIR")) candidates.push_back(std::filesystem::path(env));
  if (*RBDEM_INSTALL_DATADIR) candidates.push_back(std::filesystem::path(RBDEM_INSTALL_DATADIR) / "python");
  if (*RBDEM_SOURCE_DIR) candidates.push_back(std::filesystem::path(RBDEM_SOURCE_DIR) / "python");
  for (const auto& dir : candidates)
    if (std::filesystem::exists(dir / "rbdem_figures.py")) return dir / "rbdem_figures.py";
  return {};
}

std::vector<std::filesystem::path> make_figures(const StudySpec& spec, const std::vector<CaseResult>& results,
                                                const std::filesystem::path& out, std::string* note) {
  const auto script = figure_script();
  if (script.empty()) {
    if (note) *note = "figures skipped: python/rbdem_figures.py not found";
    return {};
  }
  const std::string python = quote(figure_python());
  const std::string cmd = python + " " + quote(script);
  // Each figure's arguments, in report order.
  std::vector<std::vector<std::string>> figures;
  const ProtocolInfo& test = protocol_info(spec.test);
  if (test.tensile) {  // tensile strength versus the layers' angle to the load
    figures.push_back({"tensile", (out / "tensile_strength.png").string(), (out / "table.csv").string()});
  } else {  // strength versus dip with Jaeger, one curve per group
    figures.push_back({"strength", (out / "strength.png").string(), (out / "table.csv").string(), "--group", "group"});
  }
  if (test.confined)  // sigma_1 against sigma_3 per dip, with Jaeger's lines
    figures.push_back({"envelope", (out / "envelope.png").string(), (out / "table.csv").string(),
                       (out / "envelope.csv").string()});
  // Stress-strain curves and crack maps per group.
  std::map<std::string, std::vector<const CaseResult*>> groups;
  std::vector<std::string> order;
  for (const auto& r : results) {
    if (!groups.count(r.c.group)) order.push_back(r.c.group);
    groups[r.c.group].push_back(&r);
  }
  for (const auto& g : order) {
    std::string safe;
    if (!g.empty()) safe.push_back('_');
    for (char c : g) safe.push_back((std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_') ? c : '_');
    std::vector<std::string> dirs, labels = {"--labels"};
    for (const auto* r : groups[g]) {
      dirs.push_back((out / r->c.id).string());
      labels.push_back(fmt::format("{:g} deg", r->c.beta));
    }
    auto figure = [&](const std::string& kind, const std::string& stem, bool with_labels) {
      std::vector<std::string> args = {kind, (out / (stem + safe + ".png")).string()};
      args.insert(args.end(), dirs.begin(), dirs.end());
      if (with_labels) args.insert(args.end(), labels.begin(), labels.end());
      figures.push_back(std::move(args));
    };
    figure("stress-strain", "stress_strain", true);
    figure("crack-grid", "cracks", false);
    // The signals of each case (docs/outputs.md): stages on the curve (compression tests), crack orientations,
    // crack rate, fragments.
    if (!test.tensile) figure("stages", "stages", true);
    figure("rose", "rose", true);
    figure("crack-rate", "crack_rate", true);
    figure("fragments", "fragments", true);
  }
  // One Python process draws them all, one figure per core at a time (`batch`: the workers share its imports, and
  // each figure takes 0.1-1.7 s, most of it matplotlib's drawing; docs/performance.md, "The serial parts of a short
  // run"). It prints `drawn FILE` for each figure it made.
  const auto list = out / ".figures.jsonl", log = out / ".figures.log";
  {
    std::ofstream f(list);
    for (const auto& args : figures) f << nlohmann::json(args).dump() << "\n";
  }
  const unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
  const int status =
      std::system(fmt::format("{} batch {} --jobs {} > {} 2>&1", cmd, quote(list), jobs, quote(log)).c_str());
  std::set<std::string> drawn;
  {
    std::ifstream f(log);
    for (std::string line; std::getline(f, line);)
      if (line.rfind("drawn ", 0) == 0) drawn.insert(line.substr(6));
  }
  std::error_code ec;
  std::filesystem::remove(list, ec), std::filesystem::remove(log, ec);
  std::vector<std::filesystem::path> made;
  for (const auto& args : figures)
    if (drawn.count(args[1])) made.push_back(args[1]);
  // Exit status 2: the script could not import matplotlib, h5py or numpy, and drew nothing.
  if (note && made.empty())
    *note = status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 2
                ? "figures skipped: " + figure_python() +
                      " lacks matplotlib, h5py or numpy (apt-get install python3-matplotlib python3-h5py "
                      "python3-numpy, or set RBDEM_PYTHON to a Python that has them)"
                : "figures failed: run `" + cmd + " --help` to check the script";
  return made;
}

namespace {
std::string compression_section(const std::vector<CaseResult>& results, const std::vector<GroupSummary>& groups,
                                const ReportExtras& extras);
std::string brazilian_section(const std::vector<CaseResult>& results, const std::vector<PointResult>* points);

// A summary value in MPa or as a ratio, "-" where it is null (not defined) or absent (a run of an older rbdem).
std::string defined_or_dash(const nlohmann::json& s, const char* key, double scale, const char* format) {
  if (!s.contains(key) || !s[key].is_number()) return "-";
  return fmt::format(fmt::runtime(format), s[key].get<double>() * scale);
}

// The signals of each case (docs/theory.md, section 10): Poisson's ratio at half the peak, crack initiation and
// crack damage stresses against the peak, the residual strength, the fragments at the end.
std::string signals_table(const std::vector<CaseResult>& results) {
  // A 3D study's volumetric strain has twice the (radial) lateral strain and its fragments are volumes.
  bool solid = false;
  for (const auto& r : results) solid = solid || r.summary.value("dimension", 2) == 3;
  std::string md = "\n### Stages and fragments\n\n";
  md += "Poisson's ratio: tangent -d eps_l / d eps_a between 40 and 60 % of the peak. Crack initiation: the onset "
        "of uninterrupted cracking (every 2 % stress bin up to the peak holds a crack); crack damage: the reversal "
        "of the volumetric strain ";
  md += solid ? "eps_a + 2 eps_l (3D: eps_l the radial strain)" : "eps_a + eps_l";
  md += " before the peak; residual: the mean stress over the last fifth of "
        "a post-peak range that reached loading.post_peak_strain or loading.max_strain; '-': not defined "
        "(docs/outputs.md). Laboratory brittle rock: initiation at 0.3-0.5 and damage at 0.7-0.9 of the peak.\n\n";
  md += "| case | beta (deg) | Poisson | initiation (MPa) | initiation / peak | damage (MPa) | damage / peak | "
        "residual (MPa) | fragments | largest fragment (" + std::string(solid ? "volume" : "area") + " fraction) |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& r : results) {
    const auto& s = r.summary;
    const nlohmann::json none = nlohmann::json::object();
    const auto& f = s.contains("fragments") ? s["fragments"] : none;
    md += fmt::format("| {} | {:g} | {} | {} | {} | {} | {} | {} | {} | {} |\n", r.c.group.empty() ? "-" : r.c.group,
                      r.c.beta, defined_or_dash(s, "poisson_ratio_at_half_peak", 1.0, "{:.3f}"),
                      defined_or_dash(s, "crack_initiation_stress_pa", 1e-6, "{:.2f}"),
                      defined_or_dash(s, "crack_initiation_to_peak", 1.0, "{:.3f}"),
                      defined_or_dash(s, "crack_damage_stress_pa", 1e-6, "{:.2f}"),
                      defined_or_dash(s, "crack_damage_to_peak", 1.0, "{:.3f}"),
                      defined_or_dash(s, "residual_stress_pa", 1e-6, "{:.2f}"), defined_or_dash(f, "count", 1.0, "{:.10g}"),
                      defined_or_dash(f, solid ? "largest_volume_fraction" : "largest_area_fraction", 1.0, "{:.3f}"));
  }
  return md;
}

// A count of a summary (an integer, or the mean of the realizations' counts).
std::string count(const nlohmann::json& v) { return fmt::format("{:.10g}", v.get<double>()); }

// " +- 1.23 [0.99]" (MPa) after the mean of row k, with realizations; nothing without.
std::string spread_text(const std::vector<PointResult>* points, std::size_t k, bool tensile) {
  if (!points) return {};
  const SampleStats& st = tensile ? (*points)[k].tensile : (*points)[k].peak;
  return fmt::format(" +- {:.2f} [{:.2f}]", st.ci95 / 1e6, st.sd / 1e6);
}

std::string realizations_text(const std::vector<PointResult>* points) {
  if (!points || points->empty()) return {};
  return fmt::format("Each case ran on {} meshes (mesh.seed; docs/studies.md, \"Realizations\"): the rows give the "
                     "means over the realizations, the 95 % interval of the mean peak as +- t_0.975,n-1 sd / sqrt(n) "
                     "and the standard deviation in brackets; Jaeger and the group summaries use the means. Every "
                     "realization is in realizations.csv.\n\n",
                     points->front().realizations.size());
}
}  // namespace

std::filesystem::path write_report(const StudySpec& spec, const std::vector<CaseResult>& results,
                                   const std::vector<GroupSummary>& groups, const std::filesystem::path& out,
                                   const ReportExtras& extras) {
  std::string note;
  const auto figures = make_figures(spec, results, out, &note);
  std::string md;
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  md += fmt::format("# rbdem study: {}\n\n{}\n\nRun {} with {} worker(s); {} cases, {:.1f} s wall in all.\n\n",
                    spec.name, spec.description, date, extras.workers, results.size(), extras.wall_seconds);
  const Scene& b = spec.base;
  md += "## Scene\n\n";
  md += b.specimen.shape == "disc" ? fmt::format("Disc of diameter {:g} mm, ", b.specimen.diameter * 1e3)
                                    : fmt::format("Specimen {:g} x {:g} mm, ", b.specimen.width * 1e3,
                                                  b.specimen.height * 1e3);
  md += fmt::format("joint spacing {:g} mm, mesh {:g} mm. Rock bonds: E* {:g} GPa, "
                    "kn/ks {:g}, tensile {:g} MPa, cohesion {:g} MPa, friction {:g} deg, contact friction {:g}. "
                    "Joint bonds: E* {:g} GPa, kn/ks {:g}, tensile {:g} MPa, cohesion {:g} MPa, friction {:g} deg, "
                    "contact friction {:g}. Platen speed {:g} m/s, local damping {:g}. The full scene of every case "
                    "is in its folder (scene.toml, summary.json).\n\n",
                    b.joint_set.spacing * 1e3, b.mesh.size * 1e3,
                    b.rock.effective_modulus / 1e9, b.rock.stiffness_ratio, b.rock.tensile_strength / 1e6,
                    b.rock.cohesion / 1e6, b.rock.friction_deg, b.rock.contact_friction,
                    b.joint.effective_modulus / 1e9, b.joint.stiffness_ratio, b.joint.tensile_strength / 1e6,
                    b.joint.cohesion / 1e6, b.joint.friction_deg, b.joint.contact_friction,
                    b.loading.platen_velocity, b.numerics.damping);
  if (!extras.elastic_gate_markdown.empty()) md += "## Elastic gate\n\n" + extras.elastic_gate_markdown + "\n\n";
  if (protocol_info(spec.test).tensile) {
    md += brazilian_section(results, extras.points);
  } else {
    md += compression_section(results, groups, extras);
  }
  md += "\n## Figures\n\n";
  if (figures.empty()) md += note + "\n";
  for (const auto& f : figures) md += fmt::format("![{}]({})\n\n", f.stem().string(), f.filename().string());
  md += "How to read them: docs/outputs.md. Each case folder holds summary.json, curve.csv, cracks.csv, scene.toml "
        "and result.h5 with result.xdmf for ParaView.\n";
  const auto path = out / "report.md";
  io::write_text_atomic(path, md);
  return path;
}

namespace {

std::string brazilian_section(const std::vector<CaseResult>& results, const std::vector<PointResult>* points) {
  std::string md = "## Brazilian tensile strength versus the layers' angle to the load\n\n";
  md += realizations_text(points);
  md += "The tensile strength is ISRM's 2 P / (pi D t) of the peak platen load P (docs/theory.md, section 9); the "
        "layer angle is measured between the layers and the loading direction (90 deg minus the dip).\n\n";
  md += "| case | dip (deg) | layers to load (deg) | tensile strength (MPa) | peak load (kN) | failure mode | cracks "
        "rock t/s | cracks joint t/s | steps | wall (s) |\n|---|---:|---:|---:|---:|---|---:|---:|---:|---:|\n";
  for (std::size_t k = 0; k < results.size(); ++k) {
    const auto& r = results[k];
    const auto& s = r.summary;
    const auto& c = s["cracks"];
    md += fmt::format("| {} | {:g} | {:g} | {:.3f}{} | {:.2f} | {} | {}/{} | {}/{} | {} | {:.1f} |\n",
                      r.c.group.empty() ? "-" : r.c.group, r.c.beta, s.value("layer_angle_deg", 0.0),
                      s.value("tensile_strength_pa", 0.0) / 1e6, spread_text(points, k, true),
                      s.value("peak_load_n", 0.0) / 1e3, s["failure_mode"].get<std::string>(), count(c["rock_tensile"]),
                      count(c["rock_shear"]), count(c["joint_tensile"]), count(c["joint_shear"]), count(s["steps"]),
                      s.value("wall_seconds", 0.0));
  }
  return md;
}

std::string compression_section(const std::vector<CaseResult>& results, const std::vector<GroupSummary>& groups,
                                const ReportExtras& extras) {
  std::string md;
  // A value or "n/a" (Jaeger without an intact strength: no 0 or 90 deg case in the group).
  auto or_na = [](double v, double scale, const char* f) {
    return std::isfinite(v) ? fmt::format(fmt::runtime(f), v / scale) : std::string("n/a");
  };
  md += "## Peak strength versus joint dip\n\n";
  md += "Jaeger: sliding on a joint whose envelope is the bonded interface's (docs/model.md: in compression the "
        "linear part shares the traction with the parallel bond, so a sticking interface has twice the bond's "
        "cohesion), capped by the group's intact strength: its measured strength at beta = 90 deg, or at 0 deg without a "
        "90 deg case, n/a with neither (docs/theory.md, section 4). table.csv also gives "
        "Jaeger with the bonds' own cohesion and friction (jaeger_bond_pa).\n\n";
  md += realizations_text(extras.points);
  md += fmt::format("| case | beta (deg) | {} | Jaeger (MPa) | strain at peak | E50 (GPa) | failure mode | cracks "
                    "rock t/s | cracks joint t/s | steps | wall (s) |\n"
                    "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n",
                    extras.points ? "mean peak (MPa) +- 95 % [sd]" : "peak (MPa)");
  std::map<std::string, double> s90;
  for (const auto& g : groups) s90[g.group] = g.strength_90_pa;
  for (std::size_t k = 0; k < results.size(); ++k) {
    const auto& r = results[k];
    const auto& s = r.summary;
    const auto& c = s["cracks"];
    md += fmt::format("| {} | {:g} | {:.2f}{} | {} | {:.3e} | {:.1f} | {} | {}/{} | {}/{} | {} | {:.1f} |\n",
                      r.c.group.empty() ? "-" : r.c.group, r.c.beta, s["peak_stress_pa"].get<double>() / 1e6,
                      spread_text(extras.points, k, false),
                      or_na(jaeger_for(r.c.scene, r.c.beta, s90[r.c.group]), 1e6, "{:.2f}"),
                      s["strain_at_peak"].get<double>(), s["youngs_modulus_pa"].get<double>() / 1e9,
                      s["failure_mode"].get<std::string>(), count(c["rock_tensile"]), count(c["rock_shear"]),
                      count(c["joint_tensile"]), count(c["joint_shear"]), count(s["steps"]),
                      s.value("wall_seconds", 0.0));
  }
  md += "\n| group | min (MPa) at beta | Jaeger min (MPa) at beta | intact strength (MPa) | anisotropy ratio "
        "(intact / min) |\n|---|---:|---:|---:|---:|\n";
  for (const auto& g : groups)
    md += fmt::format("| {} | {:.2f} at {:g} | {} at {:.0f} | {} | {} |\n", g.group.empty() ? "-" : g.group,
                      g.min_strength_pa / 1e6, g.min_beta_deg, or_na(g.jaeger_min_pa, 1e6, "{:.2f}"),
                      g.jaeger_min_beta_deg, or_na(g.strength_90_pa, 1e6, "{:.2f}"),
                      or_na(g.anisotropy_ratio, 1.0, "{:.2f}"));
  md += signals_table(results);
  if (extras.paper_check && !groups.empty()) {
    const auto& g = groups.front();
    double s60 = 0;
    for (const auto& r : results)
      if (r.c.beta == 60.0) s60 = r.summary["peak_stress_pa"].get<double>();
    md += "\n### Against the seed paper\n\n| quantity | paper | here | within |\n|---|---:|---:|---|\n";
    md += fmt::format("| strength at 90 deg (MPa) | 50 | {:.1f} | {} (+-10 %) |\n", g.strength_90_pa / 1e6,
                      std::abs(g.strength_90_pa / 50e6 - 1) <= 0.10 ? "yes" : "NO");
    md += fmt::format("| strength at 60 deg (MPa) | 20 | {:.1f} | {} (+-15 %) |\n", s60 / 1e6,
                      std::abs(s60 / 20e6 - 1) <= 0.15 ? "yes" : "NO");
    md += fmt::format("| angle of the minimum (deg) | 60 | {:g} | {} (45, 60 or 75) |\n", g.min_beta_deg,
                      (g.min_beta_deg >= 45 && g.min_beta_deg <= 75) ? "yes" : "NO");
    md += fmt::format("| anisotropy ratio | 2.5 | {:.2f} | {} (2 to 3.5) |\n", g.anisotropy_ratio,
                      (g.anisotropy_ratio >= 2 && g.anisotropy_ratio <= 3.5) ? "yes" : "NO");
  }
  if (!extras.envelopes.empty()) {
    md += "\n### Strength envelopes (sigma_1 against sigma_3)\n\n";
    md += "Per dip, the least-squares line sigma_1 = sigma_c + k sigma_3 through the confinements run, the friction "
          "angle and cohesion it implies (phi = asin((k - 1)/(k + 1)), c = sigma_c (1 - sin phi)/(2 cos phi)), and, "
          "where sliding on the joints governs, Jaeger's slope 1 + 2 mu / ((1 - mu cot beta) sin 2 beta) beside the "
          "measured slope between sigma_3 = 0 and 10 MPa (envelope.csv; with realizations, of the mean peaks, +- its "
          "standard error).\n\n";
    md += "| dip (deg) | points | sigma_c (MPa) | slope k | phi (deg) | c (MPa) | slope 0-10 MPa | Jaeger slope | "
          "difference |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const auto& e : extras.envelopes) {
      std::string measured = "-";
      if (std::isfinite(e.slope_0_10))
        measured = std::isfinite(e.slope_0_10_se) ? fmt::format("{:.3f} +- {:.3f}", e.slope_0_10, e.slope_0_10_se)
                                                  : fmt::format("{:.3f}", e.slope_0_10);
      md += fmt::format("| {:g} | {} | {:.2f} | {:.3f} | {:.1f} | {:.2f} | {} | {} | {} |\n", e.beta_deg, e.points,
                        e.intercept_pa / 1e6, e.slope, e.friction_deg, e.cohesion_pa / 1e6, measured,
                        e.slip_range ? fmt::format("{:.3f}", e.jaeger_slope) : "(intact)",
                        e.slip_range && std::isfinite(e.slope_0_10)
                            ? fmt::format("{:+.1f} %", 100.0 * (e.slope_0_10 / e.jaeger_slope - 1.0))
                            : "-");
    }
  }
  return md;
}

}  // namespace

}  // namespace rbdem::study
