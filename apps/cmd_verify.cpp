// rbdem verify: every check of this build against theory, with its error, tolerance and cost.
//
//   rbdem verify --quick --out runs/verify     # 31 cases, about 32 s on 2 cores (CI)
//   rbdem verify --out runs/verify-full        # adds finer meshes and the strength study (several minutes)
//   rbdem verify --only 'fe\.' --out runs/v    # the cases whose name matches a regular expression
// Writes verify.json and verify.md (with figures) into --out and prints the table. Exit status 3 when a case
// fails, 2 for bad options.
#include <chrono>
#include <regex>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "compare/verify/verify.hpp"
#include "io/results.hpp"
#include "study/report.hpp"

namespace rbdem::cli {

namespace {

struct VerifyCommandOptions {
  std::string out = "runs/verify";
  bool quick = false;
  std::string only;
  bool list = false;
};

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

int run_verify_command(const VerifyCommandOptions& opt) {
  std::vector<verify::CaseSpec> cases;
  std::regex filter;
  try {
    filter = std::regex(opt.only.empty() ? std::string(".*") : opt.only);
  } catch (const std::regex_error& e) {
    throw SceneError(fmt::format("--only '{}' is not a regular expression ({}); e.g. --only 'dem\\.'", opt.only,
                                 e.what()));
  }
  for (auto& c : verify::catalogue())
    if ((!opt.quick || c.quick) && std::regex_search(c.name, filter)) cases.push_back(std::move(c));
  if (opt.list) {
    for (const auto& c : cases) fmt::print("{}{}\n", c.name, c.quick ? "" : "  (full only)");
    return ok;
  }
  if (cases.empty())
    throw SceneError(fmt::format("--only '{}' matches no case; `rbdem verify --list` lists them", opt.only));
  const std::filesystem::path out(opt.out);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw SceneError(fmt::format("--out {}: cannot create the folder ({})", opt.out, ec.message()));

  verify::Context ctx;
  ctx.quick = opt.quick;
  ctx.out = out;
  ctx.log = [](const std::string& s) { fmt::print("{}\n", s); };
  fmt::print("verify: {} cases ({})\n", cases.size(), opt.quick ? "quick" : "full");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<verify::CaseResult> results;
  for (const auto& c : cases) {
    verify::CaseResult r = verify::run_case(c, ctx);
    fmt::print("  {:<30} {:>4}  error {:<10.3g} tolerance {:<10.3g} {:6.2f} s{}\n", r.name,
               verify::verdict_name(r.verdict), r.error, r.tolerance, r.seconds,
               r.failure.empty() ? "" : "  (" + r.failure + ")");
    std::fflush(stdout);
    results.push_back(std::move(r));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Figures of the cases that left data for one (python/rbdem_figures.py; skipped without matplotlib).
  const auto script = study::figure_script();
  for (auto& r : results) {
    if (r.figure.empty()) continue;
    const auto csv = out / (std::filesystem::path(r.figure).stem().string() + ".csv");
    const std::string cmd = fmt::format("{} {} fields {} {} --title '{}' > /dev/null 2>&1", quote(study::figure_python()),
                                        quote(script), quote(out / r.figure), quote(csv), r.name);
    if (script.empty() || std::system(cmd.c_str()) != 0) r.figure.clear();
  }

  io::write_text_atomic(out / "verify.json", verify::verify_json(results, ctx, seconds).dump(1) + "\n");
  io::write_text_atomic(out / "verify.md", verify::verify_markdown(results, ctx, seconds));
  int failed = 0;
  for (const auto& r : results) failed += r.verdict == verify::Verdict::fail;
  fmt::print("verify: {} of {} cases failed, {:.1f} s; report {}\n", failed, results.size(), seconds,
             (out / "verify.md").string());
  return failed ? check_failed : ok;
}

}  // namespace

Runner add_verify_command(CLI::App& app) {
  auto opt = std::make_shared<VerifyCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "verify", "every check against theory: verify.json and a report with errors, tolerances and costs");
  cmd->add_option("--out,-o", opt->out, "output folder (verify.json, verify.md, figures)")->capture_default_str();
  cmd->add_flag("--quick", opt->quick, "the fast subset (about 30 s on 2 cores; what CI runs)");
  cmd->add_option("--only", opt->only, "run only the cases whose name matches this regular expression");
  cmd->add_flag("--list", opt->list, "list the cases and exit");
  return [opt]() { return run_verify_command(*opt); };
}

}  // namespace rbdem::cli
