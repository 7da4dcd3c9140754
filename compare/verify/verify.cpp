// The verification catalogue, the runner and the reports (verify.json, verify.md).
#include "compare/verify/verify.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <thread>

#include <fmt/format.h>

#include "dem/version.hpp"

namespace rbdem::verify {

const char* verdict_name(Verdict v) {
  switch (v) {
    case Verdict::pass: return "pass";
    case Verdict::fail: return "fail";
    case Verdict::info: return "info";
  }
  return "?";
}

void CaseResult::decide() {
  if (!failure.empty()) verdict = Verdict::fail;
  else if (std::isnan(tolerance)) verdict = Verdict::info;
  else verdict = !std::isnan(error) && error <= tolerance ? Verdict::pass : Verdict::fail;
}

CaseSpec make_case(std::string name, bool quick, CaseResult (*measure)(const Context&)) {
  return CaseSpec{name, quick, [measure, name](const Context& c) {
                    CaseResult r = measure(c);
                    r.name = name;
                    return r;
                  }};
}

std::vector<CaseSpec> catalogue() {
  std::vector<CaseSpec> all;
  for (auto group : {theory_cases(), dem_cases(), reference_cases(), continuum_cases(), dim3_cases(), disc_cases(),
                      strength_cases()})
    for (auto& c : group) all.push_back(std::move(c));
  return all;
}

double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) sx += x[k], sy += y[k], sxx += x[k] * x[k], sxy += x[k] * y[k];
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

CaseResult run_case(const CaseSpec& spec, const Context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  CaseResult r;
  try {
    r = spec.run(ctx);
  } catch (const std::exception& e) {
    r.failure = e.what();
  }
  r.name = spec.name;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.decide();
  return r;
}

namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string cell(double v) {
  if (std::isnan(v)) return "-";
  if (v == 0) return "0";
  return fmt::format("{:.4g}", v);
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

std::string table_md(const nlohmann::json& rows) {
  if (!rows.is_array() || rows.empty()) return "";
  std::vector<std::string> keys;
  for (const auto& row : rows)
    for (auto it = row.begin(); it != row.end(); ++it)
      if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) keys.push_back(it.key());
  std::string s = "|";
  for (const auto& k : keys) s += " " + k + " |";
  s += "\n|";
  for (std::size_t i = 0; i < keys.size(); ++i) s += "---|";
  s += "\n";
  for (const auto& row : rows) {
    s += "|";
    for (const auto& k : keys) {
      if (!row.contains(k)) s += " |";
      else if (row[k].is_number_float()) s += " " + cell(row[k].get<double>()) + " |";
      else if (row[k].is_string()) s += " " + row[k].get<std::string>() + " |";
      else s += " " + row[k].dump() + " |";
    }
    s += "\n";
  }
  return s;
}

}  // namespace

nlohmann::json verify_json(const std::vector<CaseResult>& results, const Context& ctx, double seconds) {
  nlohmann::json j;
  j["version"] = version_text();
  j["mode"] = ctx.quick ? "quick" : "full";
  j["date"] = utc_now();
  j["hardware_threads"] = std::thread::hardware_concurrency();
  j["seconds"] = seconds;
  int passed = 0, failed = 0, info = 0;
  j["cases"] = nlohmann::json::array();
  for (const auto& r : results) {
    (r.verdict == Verdict::pass ? passed : r.verdict == Verdict::fail ? failed : info) += 1;
    nlohmann::json c;
    c["name"] = r.name;
    c["checks"] = r.checks;
    c["reference"] = r.reference;
    c["measured"] = number(r.measured);
    c["reference_value"] = number(r.reference_value);
    c["unit"] = r.unit;
    c["error"] = number(r.error);
    c["error_definition"] = r.error_definition;
    c["tolerance"] = number(r.tolerance);
    c["tolerance_source"] = r.tolerance_source;
    c["verdict"] = verdict_name(r.verdict);
    c["passed"] = r.verdict != Verdict::fail;
    c["wall_seconds"] = r.seconds;
    c["cost"] = r.cost;
    c["details"] = r.table;
    if (!r.figure.empty()) c["figure"] = r.figure;
    if (!r.failure.empty()) c["failure"] = r.failure;
    j["cases"].push_back(std::move(c));
  }
  j["passed"] = passed, j["failed"] = failed, j["informational"] = info;
  j["all_passed"] = failed == 0;
  return j;
}

std::string verify_markdown(const std::vector<CaseResult>& results, const Context& ctx, double seconds) {
  int failed = 0;
  for (const auto& r : results) failed += r.verdict == Verdict::fail;
  std::string s = fmt::format("# rbdem verification report ({})\n\n", ctx.quick ? "quick" : "full");
  s += fmt::format("Run {} on {} hardware threads: {} cases, {} failed, {:.1f} s wall.\n\n", utc_now(),
                   std::thread::hardware_concurrency(), results.size(), failed, seconds);
  s += "Each case measures one quantity against a closed form or an independent reference. The tolerance comes "
       "from round-off, from the discretisation of the method at the chosen resolution, or is marked "
       "informational where the model and the reference differ in form (then the difference is reported, not "
       "gated). `verify.json` holds the same data.\n\n";
  s += "| case | measured | reference | error | tolerance | verdict | wall (s) | cost |\n"
       "|---|---:|---:|---:|---:|---|---:|---|\n";
  for (const auto& r : results)
    s += fmt::format("| {} | {} | {} | {} | {} | **{}** | {:.2f} | {} |\n", r.name, cell(r.measured),
                     cell(r.reference_value), cell(r.error), cell(r.tolerance), verdict_name(r.verdict), r.seconds,
                     r.cost);
  for (const auto& r : results) {
    s += fmt::format("\n## {} ({})\n\n", r.name, verdict_name(r.verdict));
    s += fmt::format("- Checks: {}\n- Reference: {}\n- Error: {} = {}\n- Tolerance: {} ({})\n- Cost: {}, {:.2f} s\n",
                     r.checks, r.reference, r.error_definition, cell(r.error), cell(r.tolerance),
                     r.tolerance_source, r.cost, r.seconds);
    if (*r.unit) s += fmt::format("- Unit of measured and reference: {}\n", r.unit);
    if (!r.failure.empty()) s += fmt::format("- **Failed with:** {}\n", r.failure);
    const std::string t = table_md(r.table);
    if (!t.empty()) s += "\n" + t;
    if (!r.figure.empty()) s += fmt::format("\n![{}]({})\n", r.name, r.figure);
  }
  return s;
}

}  // namespace rbdem::verify
