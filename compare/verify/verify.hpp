// `rbdem verify`: a catalogue of verification cases, each a measured value against a closed form or an
// independent reference, with its error, its tolerance and where the tolerance comes from, and its cost.
//
// A case is one function that measures; it never decides its own tolerance after the fact. Tolerances come from
// round-off (1e-9 and below), from the discretisation order of a method at the chosen resolution, or from a
// model-form difference stated in the case (and then the case is informational: it reports, it does not gate).
// Cases that need deal.II are compiled only in the deal.II build (RBDEM_HAVE_CONTINUUM); the catalogue lists
// what is available. Plain data in and out; apps/cmd_verify.cpp prints and writes.
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dem/scene.hpp"

namespace rbdem::verify {

enum class Verdict { pass, fail, info };
const char* verdict_name(Verdict v);

struct CaseResult {
  std::string name;              // e.g. "dem.objectivity"
  std::string checks;            // what it checks, one sentence
  std::string reference;         // the formula or the source of the reference value
  double measured = std::numeric_limits<double>::quiet_NaN();
  double reference_value = std::numeric_limits<double>::quiet_NaN();
  const char* unit = "";         // of measured and reference_value (a literal)
  double error = std::numeric_limits<double>::quiet_NaN();
  std::string error_definition;  // e.g. "|measured / reference - 1|, max over the seven dips"
  double tolerance = std::numeric_limits<double>::quiet_NaN();  // NaN: informational
  std::string tolerance_source;  // where the tolerance comes from
  Verdict verdict = Verdict::info;
  double seconds = 0;            // wall time of the case
  std::string cost;              // the size of the case (blocks, DoFs, steps, mesh size)
  nlohmann::json table = nlohmann::json::array();  // rows of details (per dip, per knob setting)
  std::string figure;            // path of a figure, relative to the output folder (may be empty)
  std::string failure;           // an exception that stopped the case (then verdict = fail)

  // Sets the verdict from error and tolerance: info when the tolerance is NaN, fail when the error is NaN.
  void decide();
};

struct Context {
  bool quick = true;
  std::filesystem::path out;                      // figures and data of the cases go here
  std::function<void(const std::string&)> log;    // progress (optional)
};

struct CaseSpec {
  std::string name;
  bool quick = true;  // part of --quick
  std::function<CaseResult(const Context&)> run;
};

// A case from a plain function; the result gets the case's name.
CaseSpec make_case(std::string name, bool quick, CaseResult (*measure)(const Context&));

// Every case of this build, in report order.
std::vector<CaseSpec> catalogue();

// The groups of cases (each file of cases contributes one).
std::vector<CaseSpec> dem_cases();        // cases_dem.cpp
std::vector<CaseSpec> theory_cases();     // cases_theory.cpp
std::vector<CaseSpec> continuum_cases();  // cases_fe.cpp (empty without deal.II)
std::vector<CaseSpec> dim3_cases();       // cases_3d.cpp (the FE ones need deal.II)
std::vector<CaseSpec> disc_cases();       // cases_disc.cpp (the layered ones need deal.II)
std::vector<CaseSpec> strength_cases();   // cases_strength.cpp
std::vector<CaseSpec> reference_cases();  // cases_reference.cpp (SUNDIALS ARKODE)

// The 3D paper scene as scenes/cylinder.toml holds it (the calibrated 8 mm cylinder; test
// Verify3.CylinderSceneIsTheShippedOne keeps the two the same).
Scene cylinder_scene();

// Least-squares slope of y over x (e.g. an observed order from log-log data).
double least_squares_slope(const std::vector<double>& x, const std::vector<double>& y);

// Runs one case, timing it and turning an exception into a failed case.
CaseResult run_case(const CaseSpec& spec, const Context& ctx);

// verify.json: build, machine, mode, totals and one entry per case. verify.md: the human report.
nlohmann::json verify_json(const std::vector<CaseResult>& results, const Context& ctx, double seconds);
std::string verify_markdown(const std::vector<CaseResult>& results, const Context& ctx, double seconds);

}  // namespace rbdem::verify
