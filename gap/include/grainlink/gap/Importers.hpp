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
};
void importCsv(const CsvImport &csv, const std::string &out);

} // namespace grainlink::gap
