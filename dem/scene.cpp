// Scene registry, TOML reader, overrides and printers. See scene.hpp.
#include "dem/scene.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "dem/scene_keys.hpp"

namespace rbdem {

namespace {

using scene_keys::Entry;
using scene_keys::ValueRef;

std::vector<Entry> make_registry() {
  scene_keys::Keys k;
  scene_keys::declare_geometry(k);
  scene_keys::declare_materials(k);
  scene_keys::declare_loading(k);
  scene_keys::declare_numerics(k);
  scene_keys::declare_elastic(k);
  scene_keys::declare_output(k);
  return std::move(k.entries);
}

const std::vector<Entry>& registry() {
  static const std::vector<Entry> r = make_registry();
  return r;
}

const Entry* find_entry(std::string_view key) {
  for (const auto& e : registry())
    if (e.info.key == key) return &e;
  return nullptr;
}

std::string fmt_real(double v) { return fmt::format("{:.10g}", v); }
// Shortest text that reads back to the same double (for printed scenes, which must round-trip exactly).
std::string exact_real(double v) { return fmt::format("{}", v); }

std::string range_text(const ParamInfo& p) {
  switch (p.kind) {
    case ParamKind::real:
    case ParamKind::integer:
      return fmt::format("{}{}, {}] {}", p.min_exclusive ? "(" : "[", fmt_real(p.min), fmt_real(p.max), p.unit);
    case ParamKind::boolean:
      return "true or false";
    case ParamKind::choice: {
      std::string s;
      for (const auto& c : p.choices) s += (s.empty() ? "\"" : ", \"") + c + "\"";
      return "one of " + s;
    }
    case ParamKind::text:
      return "a string";
  }
  return {};
}

// Edit distance, to suggest the key a user probably meant.
std::size_t distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

[[noreturn]] void unknown_key(std::string_view key, std::string_view origin) {
  std::string best;
  std::size_t best_d = 1000;
  for (const auto& e : registry()) {
    const std::size_t d = distance(key, e.info.key);
    if (d < best_d) best_d = d, best = e.info.key;
  }
  std::string msg = fmt::format("{}: unknown key '{}'", origin, key);
  if (best_d <= 4) msg += fmt::format("; did you mean '{}'?", best);
  msg += " (rbdem --help-scene lists every key)";
  throw SceneError(msg);
}

void check_range(const ParamInfo& p, double v, std::string_view shown) {
  const bool below = p.min_exclusive ? !(v > p.min) : !(v >= p.min);
  if (!std::isfinite(v) || below || v > p.max)
    throw SceneError(fmt::format("{} = {} is out of range: allowed {} ({})", p.key, shown, range_text(p), p.doc));
}

double parse_real(const ParamInfo& p, std::string_view value) {
  std::string s(value);
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != s.size())
    throw SceneError(fmt::format("{} = '{}' is not a number: expected a real value in {}", p.key, value,
                                 range_text(p)));
  return v;
}

void assign(Scene& scene, const Entry& e, std::string_view value) {
  const ParamInfo& p = e.info;
  ValueRef ref = e.ref(scene);
  switch (p.kind) {
    case ParamKind::real: {
      const double v = parse_real(p, value);
      check_range(p, v, value);
      *std::get<double*>(ref) = v;
      break;
    }
    case ParamKind::integer: {
      int v = 0;
      auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (ec != std::errc() || ptr != value.data() + value.size())
        throw SceneError(fmt::format("{} = '{}' is not an integer: expected {}", p.key, value, range_text(p)));
      check_range(p, v, value);
      *std::get<int*>(ref) = v;
      break;
    }
    case ParamKind::boolean: {
      if (value == "true" || value == "1") *std::get<bool*>(ref) = true;
      else if (value == "false" || value == "0") *std::get<bool*>(ref) = false;
      else throw SceneError(fmt::format("{} = '{}' is not a boolean: expected true or false", p.key, value));
      break;
    }
    case ParamKind::choice: {
      if (std::find(p.choices.begin(), p.choices.end(), value) == p.choices.end())
        throw SceneError(fmt::format("{} = '{}' is not allowed: expected {}", p.key, value, range_text(p)));
      *std::get<std::string*>(ref) = std::string(value);
      break;
    }
    case ParamKind::text:
      *std::get<std::string*>(ref) = std::string(value);
      break;
  }
}

std::string_view kind_name(ParamKind k) {
  switch (k) {
    case ParamKind::real: return "a number";
    case ParamKind::integer: return "an integer";
    case ParamKind::boolean: return "a boolean";
    case ParamKind::choice:
    case ParamKind::text: return "a string";
  }
  return "";
}

// A TOML value as the user wrote it, for messages.
std::string shown(const toml::node& node) {
  std::ostringstream out;
  node.visit([&out](const auto& v) {
    if constexpr (toml::is_string<decltype(v)>) out << '"' << v.get() << '"';
    else if constexpr (toml::is_number<decltype(v)> || toml::is_boolean<decltype(v)>) out << v;
    else out << (v.type() == toml::node_type::array ? "(an " : "(a ") << v.type() << ")";
  });
  return out.str();
}

// One TOML value into the scene, type-checked against the registry.
void assign_toml(Scene& scene, const Entry& e, const toml::node& node, std::string_view origin) {
  const ParamInfo& p = e.info;
  auto wrong_type = [&]() {
    throw SceneError(fmt::format("{}: {} = {} has the wrong type: expected {} ({})", origin, p.key, shown(node),
                                 kind_name(p.kind), range_text(p)));
  };
  switch (p.kind) {
    case ParamKind::real: {
      double v = 0;
      if (auto f = node.as_floating_point()) v = f->get();
      else if (auto i = node.as_integer()) v = double(i->get());
      else wrong_type();
      check_range(p, v, fmt_real(v));
      *std::get<double*>(e.ref(scene)) = v;
      break;
    }
    case ParamKind::integer: {
      auto i = node.as_integer();
      if (!i) wrong_type();
      check_range(p, double(i->get()), std::to_string(i->get()));
      *std::get<int*>(e.ref(scene)) = int(i->get());
      break;
    }
    case ParamKind::boolean: {
      auto b = node.as_boolean();
      if (!b) wrong_type();
      *std::get<bool*>(e.ref(scene)) = b->get();
      break;
    }
    case ParamKind::text:
      if (const auto* items = node.as_array()) {  // a list key written as a TOML array: its items, comma separated
        std::string joined;
        for (const auto& item : *items) {
          if (!item.is_string() && !item.is_number()) wrong_type();
          const std::string text = item.is_string()  ? *item.value<std::string>()
                                   : item.is_integer() ? fmt::format("{}", *item.value<std::int64_t>())
                                                       : fmt::format("{}", *item.value<double>());  // shortest exact
          joined += (joined.empty() ? "" : ", ") + text;
        }
        assign(scene, e, joined);
        break;
      }
      [[fallthrough]];
    case ParamKind::choice: {
      auto s = node.as_string();
      if (!s) wrong_type();
      assign(scene, e, s->get());
      break;
    }
  }
}

// Records `key` as given and, when it is specimen.dimension, gives the keys whose default follows the dimension
// that dimension's default unless they were given themselves (Scene::given).
void note_given(Scene& scene, const std::string& key) {
  if (std::find(scene.given.begin(), scene.given.end(), key) == scene.given.end()) scene.given.push_back(key);
  if (key != "specimen.dimension") return;
  auto given = [&](std::string_view k) {
    return std::find(scene.given.begin(), scene.given.end(), k) != scene.given.end();
  };
  const bool solid = scene.specimen.dimension == 3;
  if (!given("specimen.shape")) scene.specimen.shape = solid ? "cylinder" : SpecimenParams{}.shape;
  if (!given("mesh.size")) scene.mesh.size = solid ? mesh3_default_size : MeshParams{}.size;
  if (!given("specimen.thickness"))
    scene.specimen.thickness = solid ? disc3_default_thickness : SpecimenParams{}.thickness;
}

}  // namespace

// Calibrated defaults for the paper's specimen (docs/calibration.md says how they were found).
Scene::Scene() {
  rock.effective_modulus = 160e9;
  rock.stiffness_ratio = 1.5;
  rock.tensile_strength = 7.51e6;
  rock.cohesion = 7.51e6;
  rock.friction_deg = 40.0;
  rock.contact_friction = 0.5;
  rock.moment_factor = 1.0;
  // Softening rock bonds that dissipate what the paper's brittle rock bonds store at their strength on its 1 mm
  // mesh (sigma_c^2 d / (2 E*) with the mean d of 0.53 mm: 0.093 J/m^2, rounded up), so that the 1 mm calibration
  // of the splitting strength holds on finer meshes too. Joint bonds stay brittle: slip along a joint is set by
  // their strength, and softening joints made it mesh-dependent (docs/performance.md, "Mesh size").
  rock.fracture_energy = 0.1;
  rock.density = 2700.0;
  joint.effective_modulus = 50e9;
  joint.stiffness_ratio = 1.5;
  joint.tensile_strength = 3.36e6;
  joint.cohesion = 3.36e6;
  joint.friction_deg = 30.0;
  joint.contact_friction = 0.5;
  joint.moment_factor = 1.0;
  joint.fracture_energy = 0.0;
  // The second materials start as copies of the first; a scene changes what differs.
  static_cast<MaterialParams&>(joint2) = joint;
  static_cast<RockParams&>(rock2) = rock;
  joint_set2.enabled = false;
  joint_set2.dip_deg = 0.0;
}

const std::vector<ParamInfo>& scene_parameters() {
  static const std::vector<ParamInfo> infos = [] {
    std::vector<ParamInfo> v;
    for (const auto& e : registry()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

void set_parameter(Scene& scene, std::string_view key, std::string_view value) {
  const Entry* e = find_entry(key);
  if (!e) unknown_key(key, "--set");
  assign(scene, *e, value);
  note_given(scene, e->info.key);
}

void apply_override(Scene& scene, std::string_view assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0)
    throw SceneError(fmt::format("--set '{}': expected section.key=value, e.g. --set rock.cohesion=20e6", assignment));
  auto trim = [](std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    if (s.size() >= 2 && ((s.front() == '"' && s.back() == '"') || (s.front() == '\'' && s.back() == '\'')))
      s = s.substr(1, s.size() - 2);
    return s;
  };
  set_parameter(scene, trim(assignment.substr(0, eq)), trim(assignment.substr(eq + 1)));
}

Scene parse_scene(std::string_view toml_text, std::string_view origin) {
  toml::table root;
  try {
    root = toml::parse(toml_text, origin);
  } catch (const toml::parse_error& err) {
    throw SceneError(fmt::format("{}:{}:{}: TOML syntax error: {}", origin, err.source().begin.line,
                                 err.source().begin.column, err.description()));
  }
  Scene scene;
  for (const auto& [section, node] : root) {
    const auto* table = node.as_table();
    if (!table)
      throw SceneError(fmt::format("{}: top-level key '{}' must be a [section] table (sections: specimen, "
                                   "joint_set, joint_set2, mesh, rock, joint, joint2, rock2, beds, loading, numerics, elastic, "
                                   "output)",
                                   origin, section.str()));
    for (const auto& [name, value] : *table) {
      const std::string key = std::string(section.str()) + "." + std::string(name.str());
      const Entry* e = find_entry(key);
      if (!e) unknown_key(key, origin);
      assign_toml(scene, *e, value, origin);
      note_given(scene, key);
    }
  }
  validate(scene);
  return scene;
}

Scene load_scene_file(const std::filesystem::path& path) {
  // A folder opens as an empty stream on Linux and would silently give the defaults.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw SceneError(fmt::format("scene file '{}' is a folder: give a TOML scene file (shipped scenes are in scenes/)",
                                 path.string()));
  std::ifstream in(path);
  if (!in)
    throw SceneError(fmt::format("cannot read scene file '{}': check the path (shipped scenes are in scenes/)",
                                 path.string()));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_scene(buffer.str(), path.string());
}

double second_set_dip_deg(const Scene& scene, double first_dip_deg) {
  const double dip = std::fmod(scene.joint_set2.follows_set1 ? first_dip_deg + scene.joint_set2.dip_deg
                                                             : scene.joint_set2.dip_deg,
                               180.0);
  return dip < 0 ? dip + 180.0 : dip;
}

namespace {
// The items of a comma separated list, trimmed; empty items dropped.
std::vector<std::string> list_items(const std::string& list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    std::string t = list.substr(start, comma - start);
    const auto first = t.find_first_not_of(" \t"), last = t.find_last_not_of(" \t");
    if (first != std::string::npos) out.push_back(t.substr(first, last - first + 1));
    start = comma + 1;
  }
  return out;
}
}  // namespace

double BedSequence::period() const {
  double t = 0;
  for (double h : thickness) t += h;
  return t;
}

std::size_t BedSequence::bed_at(double s) const {
  const double T = period();
  double u = s - start;
  u -= T * std::floor(u / T);  // in [0, T)
  for (std::size_t k = 0; k + 1 < thickness.size(); ++k) {
    if (u < thickness[k]) return k;
    u -= thickness[k];
  }
  return thickness.size() - 1;
}

BedSequence bed_sequence(const Scene& scene) {
  BedSequence beds;
  for (const std::string& name : list_items(scene.beds.pattern)) {
    if (name != "rock" && name != "rock2")
      throw SceneError(fmt::format("beds.pattern names '{}', which is not a rock of the scene: list rock and rock2 "
                                   "in the order of the beds along the joint normal, e.g. pattern = [\"rock\", "
                                   "\"rock2\"]",
                                   name));
    beds.rock2.push_back(name == "rock2");
  }
  const std::vector<std::string> thickness = list_items(scene.beds.thickness);
  if (beds.empty()) {
    if (!thickness.empty())
      throw SceneError(fmt::format("beds.thickness = \"{}\" is given without beds.pattern: name the rock of each "
                                   "bed in beds.pattern, or remove beds.thickness",
                                   scene.beds.thickness));
    return beds;
  }
  if (!thickness.empty() && thickness.size() != beds.rock2.size())
    throw SceneError(fmt::format("beds.thickness and beds.pattern differ in length ({} thicknesses, {} beds): give "
                                 "one thickness per bed, or none for beds one joint_set.spacing ({} m) thick",
                                 thickness.size(), beds.rock2.size(), fmt_real(scene.joint_set.spacing)));
  for (const std::string& t : thickness) {
    char* end = nullptr;
    const double h = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size() || !(h > 0) || !std::isfinite(h))
      throw SceneError(fmt::format("beds.thickness has '{}', which is not a positive thickness in m: write one "
                                   "positive number per bed, e.g. thickness = [0.005, 0.01]",
                                   t));
    beds.thickness.push_back(h);
  }
  if (thickness.empty()) beds.thickness.assign(beds.rock2.size(), scene.joint_set.spacing);
  beds.start = scene.joint_set.offset + scene.beds.origin;
  return beds;
}

bool uses_rock2(const Scene& scene) {
  if (!scene.rock2.groups.empty()) return true;
  for (const std::string& name : list_items(scene.beds.pattern))
    if (name == "rock2") return true;
  return false;
}

// The cross-key rules of [beds]: one way to place rock2, beds between the through-going joints of a generated
// specimen.
static void validate_beds(const Scene& scene) {
  const BedSequence beds = bed_sequence(scene);
  if (beds.empty()) return;
  if (!scene.rock2.groups.empty())
    throw SceneError(fmt::format("the scene places rock2 twice: by layer (rock2.groups = \"{}\") and by position "
                                 "(beds.pattern = \"{}\"): keep one; beds.pattern gives the same beds at every dip",
                                 scene.rock2.groups, scene.beds.pattern));
  if (!scene.mesh.file.empty())
    throw SceneError(fmt::format("beds.pattern places beds along the generated joint set's normal; a user mesh "
                                 "(mesh.file = \"{}\") names its own layers: list the rock2 layers in rock2.groups "
                                 "instead",
                                 scene.mesh.file));
  if (!scene.joint_set.enabled || scene.joint_set.persistence < 1.0)
    throw SceneError(fmt::format("beds.pattern gives each layer between the joints of joint_set its rock, and needs "
                                 "through-going joints (joint_set.enabled = {}, joint_set.persistence = {}): enable "
                                 "the joint set with persistence 1, or remove [beds]",
                                 scene.joint_set.enabled, fmt_real(scene.joint_set.persistence)));
}

void validate(const Scene& scene) {
  scene_keys::validate_dimension(scene);
  validate_beds(scene);
  Scene copy = scene;
  for (const auto& e : registry()) {
    const ParamInfo& p = e.info;
    ValueRef ref = e.ref(copy);
    if (p.kind == ParamKind::real) {
      const double v = *std::get<double*>(ref);
      check_range(p, v, fmt_real(v));
    } else if (p.kind == ParamKind::integer) {
      const int v = *std::get<int*>(ref);
      check_range(p, v, std::to_string(v));
    } else if (p.kind == ParamKind::choice) {
      const std::string& v = *std::get<std::string*>(ref);
      if (std::find(p.choices.begin(), p.choices.end(), v) == p.choices.end())
        throw SceneError(fmt::format("{} = '{}' is not allowed: expected {}", p.key, v, range_text(p)));
    }
  }
  if (scene.specimen.dimension == 3) {
    // the solid's size rule is scene_keys::validate_dimension's
  } else if (scene.specimen.shape == "disc") {
    if (scene.mesh.size > 0.1 * scene.specimen.diameter)
      throw SceneError(fmt::format("mesh.size = {} m is too coarse for a disc of specimen.diameter = {} m: use at most "
                                   "a tenth of the diameter ({} m)",
                                   fmt_real(scene.mesh.size), fmt_real(scene.specimen.diameter),
                                   fmt_real(0.1 * scene.specimen.diameter)));
  } else if (scene.mesh.size > 0.25 * std::min(scene.specimen.width, scene.specimen.height)) {
    throw SceneError(fmt::format("mesh.size = {} m is too coarse for a {} x {} m specimen: use at most a quarter of "
                                 "the smaller side ({} m)",
                                 fmt_real(scene.mesh.size), fmt_real(scene.specimen.width),
                                 fmt_real(scene.specimen.height),
                                 fmt_real(0.25 * std::min(scene.specimen.width, scene.specimen.height))));
  }
  // The mesher needs at least two elements across a layer (mesh_specimen checks the same; failing here reports
  // it before any elastic gate or sweep starts). The 3D rule is scene_keys::validate_dimension's.
  const bool plane = scene.specimen.dimension == 2;
  if (plane && scene.joint_set.enabled && scene.mesh.file.empty() && scene.joint_set.spacing < 2.0 * scene.mesh.size)
    throw SceneError(fmt::format("joint_set.spacing = {} m is under two mesh sizes (mesh.size = {} m): a layer needs "
                                 "at least two elements across; use mesh.size <= {} m or a wider spacing",
                                 fmt_real(scene.joint_set.spacing), fmt_real(scene.mesh.size),
                                 fmt_real(0.5 * scene.joint_set.spacing)));
  if (plane && scene.joint_set2.enabled && scene.mesh.file.empty() &&
      scene.joint_set2.spacing < 2.0 * scene.mesh.size)
    throw SceneError(fmt::format("joint_set2.spacing = {} m is under two mesh sizes (mesh.size = {} m): use mesh.size "
                                 "<= {} m or a wider spacing",
                                 fmt_real(scene.joint_set2.spacing), fmt_real(scene.mesh.size),
                                 fmt_real(0.5 * scene.joint_set2.spacing)));
  for (const auto& [name, set] : {std::pair<const char*, const JointSetParams*>{"joint_set", &scene.joint_set},
                                  std::pair<const char*, const JointSetParams*>{"joint_set2", &scene.joint_set2}}) {
    if (!set->enabled || set->persistence >= 1.0) continue;
    if (!scene.mesh.file.empty())
      throw SceneError(fmt::format("{}.persistence = {} applies to generated specimens only (mesh.file = \"{}\"): "
                                   "draw the joint pieces in the user mesh as physical curves instead "
                                   "(docs/scene.md, \"Several joint sets and materials\")",
                                   name, fmt_real(set->persistence), scene.mesh.file));
    const double bridge = set->joint_length * (1.0 - set->persistence) / set->persistence;
    if (set->joint_length < 2.0 * scene.mesh.size || bridge < 2.0 * scene.mesh.size)
      throw SceneError(fmt::format("{0}.joint_length = {1} m with {0}.persistence = {2} gives joint pieces of {1} m "
                                   "and rock bridges of {3} m: each must span at least two mesh sizes ({4} m); "
                                   "use a longer joint_length, a persistence nearer 0.5 or a finer mesh.size",
                                   name, fmt_real(set->joint_length), fmt_real(set->persistence),
                                   fmt_real(bridge), fmt_real(2.0 * scene.mesh.size)));
  }
  if (scene.mesh.seed != 0 && !scene.mesh.file.empty())
    throw SceneError(fmt::format("mesh.seed = {} has no effect on a user mesh (mesh.file = \"{}\"): realizations "
                                 "re-mesh the specimen; use mesh.seed = 0 with a user mesh, or no mesh.file",
                                 scene.mesh.seed, scene.mesh.file));
  if (scene.loading.transit_strain_fraction > 0.0 && !scene.numerics.elastic_start)
    throw SceneError(fmt::format("loading.transit_strain_fraction = {} sets the platen speed from the static elastic "
                                 "start, and numerics.elastic_start = false: set numerics.elastic_start = true, or "
                                 "loading.transit_strain_fraction = 0 and loading.platen_velocity",
                                 fmt_real(scene.loading.transit_strain_fraction)));
  if (scene.loading.mismatch_stop > 0.0 && !(scene.loading.ramp_force_fraction > 0.0))
    throw SceneError(fmt::format("loading.mismatch_stop = {} slows the platen within the acceleration bound of "
                                 "loading.ramp_force_fraction, which is 0: set loading.ramp_force_fraction (0.02 in "
                                 "scenes/realistic.toml), or loading.mismatch_stop = 0",
                                 fmt_real(scene.loading.mismatch_stop)));
}

// Every stress of a scene is in Pa. A value in MPa or GPa written as a bare number lands a million or a billion
// times too small: below 1 MPa for a modulus (soft rocks start near 1 GPa) or below 1 kPa for a strength, pressure
// or stress (rock bonds and lab pressures start near 0.1 MPa). Generic over the key table, so a new Pa key is
// checked without a line here.
static void check_stress_units(const Scene& scene) {
  Scene copy = scene;
  for (const auto& e : registry()) {
    if (e.info.unit != "Pa") continue;
    ValueRef ref = e.ref(copy);
    const auto* v = std::get_if<double*>(&ref);
    if (!v) continue;
    const double value = **v;
    const bool modulus = e.info.key.ends_with("modulus");
    const double least = modulus ? 1e6 : 1e3;
    if (value <= 0.0 || value >= least) continue;
    const std::string fix = modulus ? fmt::format("{0}e6 if it is in MPa, {0}e9 if in GPa", fmt_real(value))
                                    : fmt::format("{0}e6 if it is in MPa", fmt_real(value));
    throw SceneError(fmt::format(
        "{0} = {1} Pa is below {2} Pa, far below any rock's {3}: every stress in a scene is in Pa, so this is almost "
        "surely a unit mistake (write {4}); pass --force to run it anyway",
        e.info.key, fmt_real(value), fmt_real(least), modulus ? "modulus" : "strength or lab pressure", fix));
  }
}

void check_plausible(const Scene& scene) {
  check_stress_units(scene);
  // A bond strength at or above its modulus means a failure strain sigma/E* >= 1: rock fails at strains of 1e-4 to
  // 1e-2, so this is almost surely a unit mistake (a modulus in GPa or MPa, a strength in Pa).
  auto check = [](const std::string& section, const MaterialParams& m) {
    for (const auto& [name, value] : {std::pair<const char*, double>{"tensile_strength", m.tensile_strength},
                                      std::pair<const char*, double>{"cohesion", m.cohesion}})
      if (value >= m.effective_modulus)
        throw SceneError(fmt::format(
            "{0}.{1} = {2} Pa is not below {0}.effective_modulus = {3} Pa: a strength at or above the modulus is "
            "almost surely a unit mistake (every stress is in Pa: write 160e9 for 160 GPa and 7.5e6 for 7.5 MPa); "
            "pass --force to run it anyway",
            section, name, fmt_real(value), fmt_real(m.effective_modulus)));
  };
  check("rock", scene.rock);
  check("joint", scene.joint);
  if (uses_rock2(scene)) check("rock2", scene.rock2);
  check("joint2", scene.joint2);
}

std::string parameter_text(const Scene& scene, std::string_view key) {
  const Entry* e = find_entry(key);
  if (!e) unknown_key(key, "parameter_text");
  Scene copy = scene;
  ValueRef ref = e->ref(copy);
  return std::visit(
      [](auto* v) -> std::string {
        using T = std::remove_pointer_t<decltype(v)>;
        if constexpr (std::is_same_v<T, double>) return exact_real(*v);
        else if constexpr (std::is_same_v<T, int>) return std::to_string(*v);
        else if constexpr (std::is_same_v<T, bool>) return *v ? "true" : "false";
        else return *v;
      },
      ref);
}

std::string to_toml(const Scene& scene) {
  std::string out;
  std::string section;
  for (const auto& e : registry()) {
    const std::string& key = e.info.key;
    const auto dot = key.find('.');
    const std::string sec = key.substr(0, dot);
    if (sec != section) {
      out += fmt::format("{}[{}]\n", section.empty() ? "" : "\n", sec);
      section = sec;
    }
    std::string value = parameter_text(scene, key);
    if (e.info.kind == ParamKind::choice || e.info.kind == ParamKind::text) value = "\"" + value + "\"";
    else if (e.info.kind == ParamKind::real && value.find_first_of(".eEn") == std::string::npos) value += ".0";
    out += fmt::format("{:<20} = {:<16} # {}\n", key.substr(dot + 1), value, e.info.unit);
  }
  return out;
}

void to_json(nlohmann::json& j, const Scene& scene) {
  j = nlohmann::json::object();
  Scene copy = scene;
  for (const auto& e : registry()) {
    const std::string& key = e.info.key;
    const auto dot = key.find('.');
    nlohmann::json& slot = j[key.substr(0, dot)][key.substr(dot + 1)];
    std::visit([&slot](auto* v) { slot = *v; }, e.ref(copy));
  }
}

nlohmann::json scene_json(const Scene& scene) {
  nlohmann::json j;
  to_json(j, scene);
  return j;
}

std::string parameter_reference() {
  std::string out = fmt::format("{:<28} {:<8} {:<26} {:<14} {}\n", "key", "unit", "allowed", "default", "meaning");
  const Scene defaults;
  for (const auto& e : registry())
    out += fmt::format("{:<28} {:<8} {:<26} {:<14} {}\n", e.info.key, e.info.unit, range_text(e.info),
                       parameter_text(defaults, e.info.key), e.info.doc);
  return out;
}

}  // namespace rbdem
