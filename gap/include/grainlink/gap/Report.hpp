#pragma once
// The diagnosis' outputs (docs/gap.md, "Outputs"): diagnosis.json for scripts (every figure
// with its unit and interval), features.csv (every feature: measured, simulated, u_val and its
// parts, residuals, the null's and the chosen model's predictions), report.txt (the result in
// words) and report.html (self-contained, with plots; made by tools/gap_report.py).
#include "grainlink/gap/Diagnosis.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace grainlink::gap {

nlohmann::ordered_json toJson(const Diagnosis &diagnosis, const ExperimentSet &set);
std::string reportText(const Diagnosis &diagnosis, const ExperimentSet &set);

/// Writes diagnosis.json, features.csv and report.txt into `directory` (each atomically), then
/// report.html with `plot_tool` (tools/gap_report.py) if it is given and runs; returns the
/// files written. A missing Python or matplotlib costs only the HTML, with a note.
std::vector<std::string> writeDiagnosis(const Diagnosis &diagnosis, const ExperimentSet &set,
                                        const std::string &directory,
                                        const std::string &plot_tool = "");

} // namespace grainlink::gap
