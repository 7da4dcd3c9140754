// Finding and opening rbdem's modules: the libraries that are loaded (dlopen) at their first use rather than at
// start-up, because loading them costs more than most runs that never need them (continuum/fe_module.hpp: deal.II;
// dem/gmsh_module.hpp: gmsh).
//
// A module is looked for, in order: at the path in its environment variable when that is set; beside the binary
// that holds the caller (the rbdem executable, a test, the Python extension), and in ../lib from it (the build
// tree's bin/ and lib/, and an installed prefix); at the path it was built to; at the installed library directory.
// The first candidate whose table fits is used; a missing or mismatched module is an error that names every path
// tried and the fix.
#pragma once

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace rbdem::modules {

struct ModuleSpec {
  const char* file_name;      // librbdem_x.so
  const char* env;            // the environment variable that names the module's path
  const char* built;          // where the build put it
  const char* installed;      // where `cmake --install` puts it
  const char* entry;          // the module's one exported function, which returns its table
  const char* what;           // what the module is, for the error: "the gmsh mesher"
  const char* fix;            // what to do when no candidate fits
  // Resolve the module's symbols (and those of the libraries it brings) as they are first called, not all at
  // dlopen: gmsh's OpenCASCADE libraries hold far more functions than meshing calls.
  bool lazy = false;
};

// The folder of the binary this function is linked into (the executable, a test, the Python extension).
inline std::filesystem::path own_folder() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&own_folder), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::canonical(std::filesystem::path(info.dli_fname), ec);
  return ec ? std::filesystem::path(info.dli_fname).parent_path() : self.parent_path();
}

inline std::vector<std::filesystem::path> candidates(const ModuleSpec& s) {
  if (const char* env = std::getenv(s.env); env != nullptr && *env != '\0') return {std::filesystem::path(env)};
  std::vector<std::filesystem::path> c;
  if (const std::filesystem::path here = own_folder(); !here.empty()) {
    c.push_back(here / s.file_name);
    c.push_back(here.parent_path() / "lib" / s.file_name);
  }
  c.push_back(std::filesystem::path(s.built));
  c.push_back(std::filesystem::path(s.installed));
  return c;
}

// Whether a module's table was built with the caller's ABI number and struct sizes, which a default-constructed
// Table holds (its members `abi` and `sizes`).
template <class Table>
bool fits(const Table& table) {
  const Table expected;
  return table.abi == expected.abi &&
         std::equal(std::begin(table.sizes), std::end(table.sizes), std::begin(expected.sizes));
}

// The table of the first candidate that fits. Never closed: the module stays loaded until the process ends.
template <class Table>
const Table* load(const ModuleSpec& s) {
  std::string tried;
  for (const std::filesystem::path& path : candidates(s)) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      tried += "\n  " + path.string() + " (not found)";
      continue;
    }
    void* handle = dlopen(path.c_str(), (s.lazy ? RTLD_LAZY : RTLD_NOW) | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      tried += "\n  " + path.string() + " (" + (why ? why : "dlopen failed") + ")";
      continue;
    }
    using Entry = const Table* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, s.entry));
    const Table* table = entry ? entry() : nullptr;
    if (table != nullptr && fits(*table)) return table;
    tried += "\n  " + path.string() + " (built from another version of rbdem)";
  }
  throw std::runtime_error(std::string(s.what) + " (" + s.file_name + ") could not be loaded; tried:" + tried + "\n" +
                           s.fix);
}

// The table of module `Table`, loaded at the first call (thread-safe); a failed load throws and the next call tries
// again.
template <class Table>
const Table& load_once(const ModuleSpec& s) {
  static std::once_flag once;
  static const Table* table = nullptr;
  std::call_once(once, [&s] { table = load<Table>(s); });
  return *table;
}

}  // namespace rbdem::modules
