// The version of rbdem that produced a result: written into every summary.json, elastic.json and verify.json,
// printed by `rbdem --version`, and part of the elastic gate's cache key. The definitions are generated at build
// time (cmake/version.cmake).
#pragma once

#include <string>

namespace rbdem {

// The release, e.g. "0.2.0" (CMakeLists.txt, project()).
const char* version();

// The git commit of the sources, 12 hex digits, with "-dirty" when tracked files were modified; "" when the sources
// are not a git checkout.
const char* version_commit();

// "0.2.0+3ed1d54b2c7a" (semantic versioning's build metadata), or "0.2.0" without a commit.
inline std::string version_text() {
  const std::string c = version_commit();
  return c.empty() ? std::string(version()) : std::string(version()) + "+" + c;
}

}  // namespace rbdem
