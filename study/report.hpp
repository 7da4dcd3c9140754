// The study report: a Markdown page with the tables, the theory beside them, the figures and the cost.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "study/study.hpp"

namespace rbdem::study {

struct ReportExtras {
  std::string elastic_gate_markdown;  // the elastic gate's table, if it ran
  double wall_seconds = 0;            // the whole study
  int workers = 1;
  bool paper_check = false;           // compare with the seed paper's headline numbers (default dip study)
  std::vector<Envelope> envelopes;    // a confined study's strength envelopes (write_envelopes)
  const std::vector<PointResult>* points = nullptr;  // with realizations: the spread of each case (its mean is a row)
};

// Runs the figure script (python/rbdem_figures.py with figure_python()) for the study: stress-strain
// curves per group, strength versus dip with Jaeger's curve, crack maps. Returns the figure paths made (empty when
// Python or matplotlib is missing: the report then says so).
std::vector<std::filesystem::path> make_figures(const StudySpec& spec, const std::vector<CaseResult>& results,
                                                const std::filesystem::path& out, std::string* note = nullptr);

// Writes out/report.md and returns its path. `results` are one row per case: with realizations, the means
// (realization_means) and extras.points their spread.
std::filesystem::path write_report(const StudySpec& spec, const std::vector<CaseResult>& results,
                                   const std::vector<GroupSummary>& groups, const std::filesystem::path& out,
                                   const ReportExtras& extras);

// The figure script, searched in $RBDEM_PYTHON_DIR, the install prefix and the source tree.
std::filesystem::path figure_script();
// The Python that runs it: $RBDEM_PYTHON when set, else the python3 on PATH when it imports matplotlib, h5py and
// numpy, else Debian's /usr/bin/python3. Unquoted.
std::string figure_python();

}  // namespace rbdem::study
