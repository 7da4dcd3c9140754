// The front library's deal.II functions: each loads the module librbdem_fe.so once (see fe_module.hpp for why and
// where it is looked for) and calls its definition through the module's table.
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "continuum/fe_module.hpp"

namespace rbdem::continuum {

namespace {

namespace fs = std::filesystem;

// The folder of the binary this function is linked into (the executable, a test, the Python extension).
fs::path own_folder() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&own_folder), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const fs::path self = fs::canonical(fs::path(info.dli_fname), ec);
  return ec ? fs::path(info.dli_fname).parent_path() : self.parent_path();
}

std::vector<fs::path> candidates() {
  const std::string name = RBDEM_FE_MODULE_NAME;
  std::vector<fs::path> c;
  if (const char* env = std::getenv("RBDEM_FE_MODULE"); env != nullptr && *env != '\0') return {fs::path(env)};
  if (const fs::path here = own_folder(); !here.empty()) {
    c.push_back(here / name);
    c.push_back(here.parent_path() / "lib" / name);
  }
  c.push_back(fs::path(RBDEM_FE_MODULE_BUILT));
  c.push_back(fs::path(RBDEM_FE_MODULE_INSTALLED));
  return c;
}

const FeModule* load() {
  std::string tried;
  for (const fs::path& path : candidates()) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      tried += "\n  " + path.string() + " (not found)";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      tried += "\n  " + path.string() + " (" + (why ? why : "dlopen failed") + ")";
      continue;
    }
    using Entry = const FeModule* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "rbdem_fe_module"));
    const FeModule* m = entry ? entry() : nullptr;
    const FeModule expected;
    bool same = m != nullptr && m->abi == expected.abi;
    for (int k = 0; same && k < 6; ++k) same = m->sizes[k] == expected.sizes[k];
    if (same) return m;
    tried += "\n  " + path.string() + " (built from another version of rbdem)";
  }
  throw std::runtime_error(
      "the deal.II continuum model (" RBDEM_FE_MODULE_NAME ") could not be loaded; tried:" + tried +
      "\nRebuild rbdem with deal.II (scripts/setup.sh build), or set RBDEM_FE_MODULE to the module's path");
}

const FeModule& module() {
  static std::once_flag once;
  static const FeModule* m = nullptr;
  std::call_once(once, [] { m = load(); });  // a throw leaves the flag unset: the next call tries again
  return *m;
}

}  // namespace

FeResult solve_elastic(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double thickness,
                       const FeOptions& options) {
  return module().solve_elastic(mesh, c, bedding_deg, thickness, options);
}

JointedFeResult solve_elastic_jointed(const TriMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                      double bedding_deg, const std::vector<InterfaceEdge>& interfaces,
                                      double thickness, const JointedFeOptions& options) {
  return module().solve_elastic_jointed(mesh, layer_constants, bedding_deg, interfaces, thickness, options);
}

DiscResult solve_disc(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, theory::Plane plane,
                      double load, double thickness, const DiscOptions& options) {
  return module().solve_disc(mesh, c, bedding_deg, plane, load, thickness, options);
}

HoleResult solve_hole(const theory::TIConstants& c, double material_angle_deg, theory::Plane plane,
                      const HoleOptions& o) {
  return module().solve_hole(c, material_angle_deg, plane, o);
}

std::vector<std::pair<int, int>> layer_interface_edges(const TriMesh& mesh) {
  return module().layer_interface_edges(mesh);
}

std::vector<int> count_node_copies(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces) {
  return module().count_node_copies(mesh, interfaces);
}

std::string dealii_version() { return module().dealii_version(); }

}  // namespace rbdem::continuum
