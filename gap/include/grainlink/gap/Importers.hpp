#pragma once
// Importers that write a measurements folder (docs/gap.md): the CMU 3d-terramechanics test
// bed's plate-sinkage and steady-state single-wheel tests, and any plain CSV. The folder gets
// its own copy of the columns it uses, so it stands alone; the source is named in
// experiments.yaml.
#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

struct CmuImportOptions {
    /// Which sinkage column: "synced" (the data README's recommendation), "authors", or
    /// "deflection_corrected" (the test bed's compliance removed).
    std::string sinkage = "synced";
    bool plates = true, wheels = true;
};

/// Reads the CMU folder (plates/, steady_state_wheel/) and writes DIR/experiments.yaml with
/// one experiment per plate size and box (its trials the repeats) and one per wheel and slip
/// angle (each run a point of a slip scatter). Returns the experiment ids written.
std::vector<std::string> importCmu(const std::string &cmu_directory, const std::string &out,
                                   const CmuImportOptions &options = {});

/// Plain CSV files as one experiment, added to DIR/experiments.yaml (created if absent): one
/// file, or one file per repeat of the test (its trials).
struct CsvImport {
    std::vector<std::string> files;
    std::string id;
    std::string type;                ///< an experiment type (plate_sinkage, ...)
    std::string x_column, x_unit;    ///< empty for a scalar experiment
    std::map<std::string, std::pair<std::string, std::string>> y; ///< observable -> column, unit
    std::map<std::string, std::string> conditions; ///< key -> value (numbers stay numbers)
    bool scatter = false;
    std::string delimiter = ","; ///< ",", ";", "tab" or "whitespace"
    std::string decimal = ".";   ///< "," for numbers with a decimal comma
    std::string comment = "#";   ///< lines starting with it are skipped
    std::vector<std::string> columns; ///< the names of a file without a header line
    bool units_row = false;           ///< the line under the header holds units
    int skip_lines = 0;               ///< lines before the header (a title), skipped
    /// Multiply a column as read (-1: another code's z up); experiments.yaml's `scale:`.
    double x_scale = 1.0;
    std::map<std::string, double> y_scale; ///< observable -> its column's scale
    /// Only the rows holding these values (column -> value): one experiment of a file that
    /// holds several (a wheel's slip angles). The copy keeps just those rows.
    std::map<std::string, double> filter;
    /// The column telling apart trials written one after the other in a file (a run number):
    /// experiments.yaml's `data.trial`. Empty: each file is one trial.
    std::string trial_column;
    /// experiments.yaml's `zero:`: "" (none written: as_recorded), "as_recorded",
    /// "first_sample" or "force_threshold" with its threshold in `zero_unit`.
    std::string zero_method;
    double zero_threshold = 0.0;
    std::string zero_unit;
};
/// Returns warnings to show the user (a column that varies within the experiment, a condition
/// the simulation does not read); errors name the option or the input file, never the folder
/// being written.
std::vector<std::string> importCsv(const CsvImport &csv, const std::string &out);

} // namespace grainlink::gap
