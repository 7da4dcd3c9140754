// The protocol registry. See registry.hpp.
#include "dem/driver/registry.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rbdem {

// The built-in protocols, one line each: X(name) registers `ProtocolInfo name_protocol()` of
// dem/driver/protocols/name.cpp. (A list macro, as LAMMPS registers its styles: a protocol file is never referenced
// by name from elsewhere, and a static registrar in a static library would be dropped by the linker.)
#define RBDEM_PROTOCOLS(X) \
  X(ucs)                   \
  X(triaxial)              \
  X(brazilian)             \
  X(shear)                 \
  X(cyclic)                \
  X(hold)

#define RBDEM_DECLARE(name) ProtocolInfo name##_protocol();
RBDEM_PROTOCOLS(RBDEM_DECLARE)
#undef RBDEM_DECLARE

namespace {

std::vector<ProtocolInfo>& registry() {
#define RBDEM_ENTRY(name) name##_protocol(),
  static std::vector<ProtocolInfo> all = {RBDEM_PROTOCOLS(RBDEM_ENTRY)};
#undef RBDEM_ENTRY
  return all;
}

}  // namespace

const std::vector<ProtocolInfo>& protocols() { return registry(); }

void register_protocol(ProtocolInfo protocol) {
  for (const ProtocolInfo& p : registry())
    if (p.name == protocol.name)
      throw std::invalid_argument("a protocol named '" + protocol.name + "' is registered already");
  if (!protocol.make || !protocol.check || !protocol.headline)
    throw std::invalid_argument("protocol '" + protocol.name + "': make, check and headline are required");
  registry().push_back(std::move(protocol));
}

const ProtocolInfo& protocol_info(const std::string& name) {
  std::vector<std::string> names;
  for (const ProtocolInfo& p : protocols()) {
    if (p.name == name) return p;
    names.push_back(p.name);
  }
  throw SceneError(fmt::format("unknown test '{}': the tests are {}", name, fmt::join(names, ", ")));
}

void refuse_confining_pressure(const std::string& test, const Scene& scene) {
  if (!(scene.loading.confining_pressure > 0.0)) return;
  std::vector<std::string> confined;
  for (const ProtocolInfo& p : protocols())
    if (p.confined) confined.push_back("rbdem " + p.name);
  throw SceneError(fmt::format("loading.confining_pressure = {} Pa: only {} applies a confining pressure; use it, or "
                               "set it to 0 for rbdem {}",
                               scene.loading.confining_pressure, fmt::join(confined, ", "), test));
}

}  // namespace rbdem
