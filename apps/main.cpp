// rbdem: rigid block DEM of layered rock under uniaxial and confined compression and the Brazilian test, with its
// elastic and strength checks.
//
// Usage:
//   rbdem                                   the default study on the built-in paper scene (the same values as
//                                           scenes/paper.toml): table and report
//   rbdem --realizations 5                  the same with five meshes per dip: mean, sd, 95 % interval
//   rbdem ucs --beta 60 --out runs/b60      one uniaxial compression test
//   rbdem triaxial --beta 60 --confining 10e6 --out runs/t60   one confined compression test
//   rbdem brazilian --beta 30 --out runs/bz30                  one Brazilian test of a disc
//   rbdem sweep study.toml --out runs/s     a parameter study (resumable; mpirun spreads the cases)
//   rbdem mesh --beta 30 --out s.msh        the specimen mesh, for inspection in gmsh
//   rbdem elastic --out runs/el             DEM vs the FE model with the joints vs Amadei: the elastic gate
//   rbdem verify --quick --out runs/v       every check against theory: verify.json and verify.md
//   rbdem --help-scene                      every scene key with unit, range and default
//   rbdem <command> --help                  the options of one command
//
// Exit status: 0 done, 1 the run failed, 2 bad input, 3 a physical check failed.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "dem/simulation.hpp"
#include "dem/version.hpp"

namespace {

using namespace rbdem::cli;

std::vector<std::string> command_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  return names;
}

// CLI11 answers a mistyped command with "The following argument was not expected: ucss"; say what the word is
// instead: a command that does not exist (and the one meant), or a file given without its command.
int refuse_unknown_command(const CLI::App& app, const std::string& word) {
  const auto names = command_names(app);
  if (std::filesystem::is_regular_file(word)) {
    const InputKind kind = input_kind(word);
    fmt::print(stderr, "rbdem: error: '{0}' is a file, not a command: name the command first, {1}\n", word,
               kind == InputKind::study         ? fmt::format("`rbdem sweep {}` (it is a study)", word)
               : kind == InputKind::calibration ? fmt::format("`rbdem calibrate {}` (it is a calibration)", word)
                                                : fmt::format("e.g. `rbdem ucs {}` (a scene)", word));
    return bad_input;
  }
  const std::string near = closest(word, names, 2);
  fmt::print(stderr, "rbdem: error: unknown command '{}'{}; the commands are {} (`rbdem --help` says what each does)\n",
             word, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), fmt::join(names, ", "));
  return bad_input;
}

// An option a command does not have: name it, the command, and the option meant when one is close. False when
// the extras were no options (CLI11's own message then stands).
bool explain_extras(const CLI::App& app) {
  const CLI::App* cmd = &app;
  for (const CLI::App* sub : app.get_subcommands())
    if (sub->parsed()) cmd = sub;
  std::vector<std::string> options;
  for (const CLI::Option* o : cmd->get_options())
    for (const auto& name : o->get_lnames()) options.push_back("--" + name);
  auto extras = cmd->remaining();
  if (cmd != &app)
    for (const auto& e : app.remaining()) extras.push_back(e);
  const std::string where = cmd == &app ? "rbdem" : "rbdem " + cmd->get_name();
  bool explained = false;
  for (const auto& e : extras) {
    if (!e.starts_with("-")) continue;
    explained = true;
    const std::string name = e.substr(0, e.find('='));
    const std::string near = closest(name, options, 2);
    fmt::print(stderr, "rbdem: error: {} has no option {}{}; `{} --help` lists its options\n", where, name,
               near.empty() ? "" : fmt::format(" (did you mean {}?)", near), where);
  }
  return explained;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rbdem: rigid block DEM of transversely isotropic rock: uniaxial and confined compression, Brazilian test,\n"
               "direct shear of a joint.\n"
               "With no command, runs the default study (dips 0 to 90 deg) on the built-in paper scene (the same\n"
               "values as scenes/paper.toml).\n"
               "Units are SI (m, Pa, s, kg); angles in degrees. Exit status: 0 done, 1 run failed, 2 bad input,\n"
               "3 a physical check failed."};
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "rbdem " + rbdem::version_text(), "print the version (and the git commit of the build) and exit");
  bool help_scene = false;
  app.add_flag("--help-scene", help_scene, "list every scene key with unit, allowed range, default and meaning");
  bool print_defaults = false;
  app.add_flag("--print-scene", print_defaults, fmt::format("print {} as TOML", builtin_scene));
  int realizations = 1;
  app.add_option("--realizations", realizations,
                 "with no command: meshes per dip of the default study (mesh.seed 0 .. N-1; mean, sd and 95 % "
                 "interval per dip, into runs/default_realizations)")
      ->type_name("N");

  std::map<CLI::App*, Runner> runners;
  runners[nullptr] = nullptr;
  auto add = [&](Runner r) { runners[app.get_subcommands({}).back()] = std::move(r); };
  for (const rbdem::ProtocolInfo& test : rbdem::protocols()) add(add_test_command(app, test));
  add(add_sweep_command(app));
  add(add_calibrate_command(app));
  add(add_mesh_command(app));
  add(add_verify_command(app));
  add(add_elastic_command(app));

  // The first word that is not an option names the command (rbdem's own options take no values but
  // --realizations).
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--realizations") ++i;
    if (word.starts_with("-")) continue;
    const auto names = command_names(app);
    if (std::find(names.begin(), names.end(), word) == names.end()) return refuse_unknown_command(app, word);
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ExtrasError& e) {
    if (!explain_extras(app)) app.exit(e);
    return bad_input;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? ok : bad_input;
  }
  try {
    if (help_scene) {
      fmt::print("{}", rbdem::parameter_reference());
      return ok;
    }
    if (print_defaults) {
      fmt::print("{}", rbdem::to_toml(rbdem::Scene{}));
      return ok;
    }
    for (auto& [cmd, run] : runners)
      if (cmd && cmd->parsed()) {
        if (app.count("--realizations"))
          throw std::invalid_argument(fmt::format("--realizations goes with the default study (no command): for "
                                                  "`rbdem {0}` give realizations = N in the study's [study] table or "
                                                  "`rbdem sweep STUDY.toml --realizations N`",
                                                  cmd->get_name()));
        return run();
      }
    return run_default_job(realizations);
  } catch (const rbdem::SceneError& e) {
    fmt::print(stderr, "rbdem: error: {}\n", e.what());
    return bad_input;
  } catch (const rbdem::InstabilityError& e) {
    fmt::print(stderr, "rbdem: run failed: {}\n", e.what());
    return run_failed;
  } catch (const std::invalid_argument& e) {
    fmt::print(stderr, "rbdem: error: {}\n", e.what());
    return bad_input;
  } catch (const std::exception& e) {
    fmt::print(stderr, "rbdem: run failed: {}\n", e.what());
    return run_failed;
  }
}
