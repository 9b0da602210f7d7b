#pragma once
// A study's results as tables: every point (points.csv) and every design point with its
// observables' mean, standard deviation and standard error over the replicates (table.csv,
// table.md; tools/plot_study.py plots table.csv).
#include "grainlink/study/Study.hpp"

#include <optional>
#include <string>
#include <vector>

namespace grainlink::study {

/// The number at a dotted path of a summary (`fit.psi_deg.value`, `bodies.plate.force_N.2`);
/// none when the path is absent or does not end at a number.
std::optional<double> observable(const nlohmann::json &summary, const std::string &path);

struct Statistics {
    std::size_t n = 0;
    double mean = 0.0;
    double sd = 0.0;  ///< sample standard deviation (n - 1); NaN for n < 2
    double sem = 0.0; ///< standard error of the mean, sd / sqrt(n); NaN for n < 2
};
Statistics statistics(const std::vector<double> &values);

/// One row per design point: the varied keys' values and each observable's statistics over
/// the finished replicates.
struct TableRow {
    std::vector<std::string> settings;    ///< one per study.varied_keys
    std::size_t points = 0, finished = 0; ///< replicates in the design, and finished
    std::vector<Statistics> observables;  ///< one per study.observables
};
std::vector<TableRow> tableRows(const Study &study, const std::vector<PointResult> &results);

struct TableFiles {
    std::string points_csv, table_csv, table_md;
    std::vector<std::string> warnings; ///< observables missing from a finished point's summary
};
/// Writes points.csv, table.csv and table.md into the study folder.
TableFiles writeTables(const Study &study, const std::vector<PointResult> &results);
std::string markdownTable(const Study &study, const std::vector<TableRow> &rows);

} // namespace grainlink::study
