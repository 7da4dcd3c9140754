// Fault injection for the self-test of `rbdem verify` (tests/verify_faults.sh): the environment variable
// RBDEM_FAULT=<name> plants one known bug so that the test can check that verify catches it.
//   compliance_sign   the sign of a12 in S22 of the rotated compliance (compare/theory/elasticity.cpp)
//   bond_inertia      the parallel bond's moment of inertia t L^3 / 6 instead of t L^3 / 12 (dem/engine.cpp)
// Read once per process and only where the affected quantity is set up, never in a per-step loop.
#pragma once

#include <cstdlib>
#include <string>
#include <string_view>

namespace rbdem {

inline bool fault_injected(std::string_view name) {
  static const std::string value = [] {
    const char* v = std::getenv("RBDEM_FAULT");
    return v ? std::string(v) : std::string();
  }();
  return !value.empty() && value == name;
}

}  // namespace rbdem
