// The protocol registry: every test rbdem runs, by name. Each protocol is one file in dem/driver/protocols/ that
// defines a function `ProtocolInfo <name>_protocol()`; registry.cpp lists them, one line each. The command line,
// studies, reports, the Python module and the writers ask the registry what a test needs and what it reports;
// nothing else compares a test's name.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem/driver/protocol.hpp"
#include "dem/scene.hpp"

namespace rbdem {

struct ProtocolInfo {
  std::string name;         // the command (`rbdem <name>`) and summary.json's "test"
  std::string description;  // one line for `rbdem --help`
  // Scene keys the test sets before the user's (as --set would): the Brazilian test's disc. An explicit --set of
  // the same key comes after and is then checked by `check`.
  std::vector<std::pair<std::string, std::string>> scene_defaults;
  // The command's own options, each a shorthand for one scene key (`rbdem triaxial --confining 10e6` sets
  // loading.confining_pressure): the option ("--confining"), the key, and the help text.
  struct Shorthand {
    std::string option, key, help;
  };
  std::vector<Shorthand> options;
  // Refuses a scene that does not suit the test: a SceneError naming the key and the fix.
  std::function<void(const Scene&)> check;
  std::function<std::unique_ptr<LoadingProtocol>(const Scene& scene, int curve_points)> make;
  // How studies read the test (study/): the confining pressure is one of its axes (envelopes and Jaeger's
  // confined lines), or its result is a tensile strength against the layer angle (a disc).
  bool confined = false;
  bool tensile = false;
  // The command's result line ("ucs: peak 50.92 MPa at strain ..."), and notes to print after it.
  std::function<std::string(const TestResult&)> headline;
  std::function<std::vector<std::string>(const TestResult&)> notes;
};

// The protocol named `name`; a SceneError that lists the names when there is none.
const ProtocolInfo& protocol_info(const std::string& name);
// Every registered protocol: the built-in ones in the registry's order, then those registered at run time.
const std::vector<ProtocolInfo>& protocols();
// Registers a protocol at run time (a test's own, a script's): from then on protocol_info finds it and run_case
// runs it like a built-in one. Throws std::invalid_argument when the name is taken or a function is missing. Not
// for concurrent use with runs: register before running.
void register_protocol(ProtocolInfo protocol);

// Refuses a confining pressure for a test that does not apply one (every protocol but the confined ones).
void refuse_confining_pressure(const std::string& test, const Scene& scene);

}  // namespace rbdem
