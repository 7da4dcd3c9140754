// rbdem: rigid block DEM of layered rock under uniaxial and confined compression and the Brazilian test, with its
// elastic and strength checks.
//
// Usage:
//   rbdem                                   the default study (paper specimen), table and report
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
#include <cstdio>
#include <exception>
#include <map>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "dem/engine.hpp"
#include "dem/version.hpp"

int main(int argc, char** argv) {
  using namespace rbdem::cli;
  CLI::App app{"rbdem: rigid block DEM of transversely isotropic rock: uniaxial and confined compression, Brazilian test.\n"
               "With no command, runs the default study on the paper's specimen.\n"
               "Units are SI (m, Pa, s, kg); angles in degrees. Exit status: 0 done, 1 run failed, 2 bad input,\n"
               "3 a physical check failed."};
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "rbdem " + rbdem::version_text(), "print the version (and the git commit of the build) and exit");
  bool help_scene = false;
  app.add_flag("--help-scene", help_scene, "list every scene key with unit, allowed range, default and meaning");
  bool print_defaults = false;
  app.add_flag("--print-scene", print_defaults, "print the built-in default scene as TOML (scenes/paper.toml)");

  std::map<CLI::App*, Runner> runners;
  runners[nullptr] = nullptr;
  auto add = [&](Runner r) { runners[app.get_subcommands({}).back()] = std::move(r); };
  add(add_test_command(app, "ucs"));
  add(add_test_command(app, "triaxial"));
  add(add_test_command(app, "brazilian"));
  add(add_sweep_command(app));
  add(add_calibrate_command(app));
  add(add_mesh_command(app));
  add(add_verify_command(app));
#ifdef RBDEM_HAVE_CONTINUUM
  add(add_elastic_command(app));
#endif

  try {
    app.parse(argc, argv);
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
      if (cmd && cmd->parsed()) return run();
    return run_default_job();
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
