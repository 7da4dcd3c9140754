// The cached elastic gate. See gate_cache.hpp.
#include "compare/gate/gate_cache.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "dem/mesh_cache.hpp"
#include "io/results.hpp"
#include "dem/version.hpp"

namespace rbdem::compare {

namespace {

// Bumped whenever the gate's measurement or verdict changes meaning, so old verdicts are not reused.
// 2: the FE model with the joints decides (not Amadei), seven-dip weighted fit, linear check.
constexpr const char* gate_version = "rbdem-elastic-gate-3";

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }
bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool stiffness_scatters(const Scene& s) {
  return s.rock.stiffness_weibull_modulus > 0 || s.rock2.stiffness_weibull_modulus > 0;
}

// Scene keys that cannot change the elastic response (see the header). The strength seed does where it draws the
// bonds' stiffness factors too.
bool elastically_irrelevant(const std::string& key, const Scene& scene) {
  if (key == "joint_set.dip_deg" || key == "rock.density" || key == "rock2.density") return true;
  if (key == "mesh.strength_seed") return !stiffness_scatters(scene);
  if (ends_with(key, ".stiffness_weibull_modulus")) return false;
  if (starts_with(key, "loading.") || starts_with(key, "numerics.") || starts_with(key, "output.")) return true;
  for (const char* strength : {".tensile_strength", ".cohesion", ".friction_deg", ".moment_factor",
                               ".fracture_energy", ".weibull_modulus"})
    for (const char* material : {"rock.", "joint.", "joint2.", "rock2."})
      if (starts_with(key, material) && ends_with(key, strength)) return true;
  return false;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string summary_line(const GateVerdict& g, bool cached) {
  return fmt::format("elastic gate {}{}", g.message, cached ? " (cached)" : "");
}

}  // namespace

std::string elastic_gate_key_text(const Scene& scene) {
  // The code's version and commit too: another build may measure differently, so it never reuses a verdict.
  std::string text = std::string(gate_version) + "\n" + "rbdem=" + version_text() + "\n";
  for (const auto& p : scene_parameters())
    if (!elastically_irrelevant(p.key, scene)) text += p.key + "=" + parameter_text(scene, p.key) + "\n";
  if (!scene.mesh.file.empty())
    text += fmt::format("mesh.file.contents={:016x}\n", fnv1a(read_file(scene.mesh.file)));
  return text;
}

std::string elastic_gate_key(const Scene& scene) { return fmt::format("{:016x}", fnv1a(elastic_gate_key_text(scene))); }

std::filesystem::path elastic_gate_cache_dir() { return cache_dir(); }

std::filesystem::path store_elastic_gate(const Scene& scene, const ElasticReport& report) {
  const auto dir = elastic_gate_cache_dir();
  if (dir.empty()) return {};
  const std::string key = elastic_gate_key(scene);
  nlohmann::json j = elastic_json(report, scene);
  for (auto& a : j["angles"]) a.erase("fields");  // the verdict and its table, not the fields
  j["key"] = key;
  j["key_text"] = elastic_gate_key_text(scene);
  j["table"] = elastic_table(report);
  const auto file = dir / ("elastic-gate-" + key + ".json");
  try {
    std::filesystem::create_directories(dir);
    // A name of this process's own first: ranks of a sweep may store the same key at the same time.
    const auto mine = std::filesystem::path(file.string() + "." + std::to_string(::getpid()));
    io::write_text_atomic(mine, j.dump(1) + "\n");
    std::filesystem::rename(mine, file);
  } catch (const std::exception&) {
    return {};
  }
  return file;
}

GateCheck check_elastic_gate(const Scene& scene, const ElasticGateOptions& options) {
  GateCheck c;
  if (scene.specimen.dimension == 3) {
    c.note = "elastic gate: a 3D scene's gate is `rbdem elastic` on the scene (DEM static vs the 3D FE twin, "
             "docs/elastic.md \"Three dimensions\"); it is not run in front of 3D failure runs";
    return c;
  }
  if (!scene.mesh.file.empty()) {
    c.note = fmt::format("elastic gate: not applicable to a user mesh (mesh.file = {}): it re-meshes the "
                         "specimen at every dip",
                         scene.mesh.file);
    return c;
  }
  c.key = elastic_gate_key(scene);
  const auto dir = elastic_gate_cache_dir();
  if (!dir.empty()) {
    c.cache_file = dir / ("elastic-gate-" + c.key + ".json");
    const std::string text = read_file(c.cache_file);
    if (!text.empty()) {
      const auto j = nlohmann::json::parse(text, nullptr, false);
      if (!j.is_discarded() && j.value("key", "") == c.key && j.contains("gate") && j.contains("table")) {
        GateVerdict g;
        g.passed = j["gate"].value("passed", false);
        g.tolerance = j["gate"].value("tolerance", 0.0);
        g.measure = j["gate"].value("measure", "") == "dem_static" ? GateMeasure::platen : GateMeasure::gauge;
        g.max_deviation = j["gate"]["max_deviation"].is_number() ? j["gate"]["max_deviation"].get<double>()
                                                                : std::numeric_limits<double>::quiet_NaN();
        g.worst_beta_deg = j["gate"].value("worst_beta_deg", 0.0);
        g.comparison = j["gate"].value("comparison", "");
        g.message = j["gate"].value("message", "");
        g.reason = j["gate"].value("reason", "");
        c.status = g.passed ? GateCheck::Status::passed : GateCheck::Status::failed;
        c.from_cache = true;
        c.table = j["table"].get<std::string>();
        c.summary = summary_line(g, true);
        return c;
      }
    }
  }
  const ElasticReport report = run_elastic_gate(scene, options);
  c.status = report.gate.passed ? GateCheck::Status::passed : GateCheck::Status::failed;
  c.table = elastic_table(report);
  c.summary = summary_line(report.gate, false) + fmt::format(" in {:.1f} s", report.seconds);
  const auto stored = store_elastic_gate(scene, report);
  if (stored.empty())
    c.note = "elastic gate: the verdict was not cached (no writable cache folder; set RBDEM_CACHE_DIR)";
  return c;
}

Scene gate_scene(const Scene& scene) {
  Scene s = scene;
  s.specimen.shape = "rectangle";
  s.loading.confining_pressure = 0.0;
  s.mesh.structured = false;  // a structured grid takes horizontal joints only, and the gate turns them
  return s;
}

bool require_elastic_gate(const Scene& scene, bool quiet) {
  const GateCheck c = check_elastic_gate(scene);
  if (!c.note.empty() && !quiet) fmt::print("{}\n", c.note);
  if (c.status == GateCheck::Status::failed) {
    fmt::print("{}", c.table);
    std::fflush(stdout);
    fmt::print(stderr,
               "rbdem: {}\nrbdem: refusing the failure run: the DEM does not reproduce the elastic response of the FE "
               "model of the same blocks' rock with the joints as interfaces within elastic.tolerance "
               "(docs/elastic.md, \"What to do when the gate fails\"). Run anyway with --skip-elastic-gate.\n",
               c.summary);
    return false;
  }
  if (c.status == GateCheck::Status::passed && !quiet) fmt::print("{}\n", c.summary);
  return true;
}

}  // namespace rbdem::compare
