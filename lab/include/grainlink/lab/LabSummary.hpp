#pragma once
// The machine-readable result of a lab test: summary.json beside report.txt and the CSVs
// (format in docs/lab.md, "summary.json"). A study runner collects its design points from it and
// the sim-to-real diagnosis compares its curves with measured ones; neither reads printed text.
//
//     const lab::LabSummary s = lab::readLabSummary("out/bevameter/summary.json");
//     const double n = s.fitted("bekker", "n").value;
//     const auto &z = s.runs[0].curve("sinkage_m"), &p = s.runs[0].curve("pressure_Pa");
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace grainlink::lab {

/// The prepared bed a lab test runs on (the repose test's: the fill inside the tube).
struct LabBedSummary {
    std::size_t grains = 0;
    double largest_radius_m = 0.0;   ///< [m] largest grain radius of the deposition
    double time_step_s = 0.0;        ///< [s] the bed's DEM time step
    double floor_m = 0.0;            ///< [m] z of the bed's floor
    double surface_m = 0.0;          ///< [m] z of its surface (dem::bedSurface, 98th percentile)
    double footprint_m2 = 0.0;       ///< [m^2] horizontal area the bed fills
    double bulk_density_kg_m3 = 0.0; ///< [kg/m^3] grain mass / (footprint (surface - floor))
    double packing_fraction = 0.0;   ///< [-] bulk density / grain density
    std::uint64_t seed = 0;          ///< the deposition's seed
    bool from_cache = false;         ///< the packing came from the packing cache
    double wall_s = 0.0;             ///< [s] wall time to deposit or read the packing
};

/// One fitted parameter; its 95 % interval is value +- half_width_95.
struct FittedValue {
    std::string name; ///< e.g. "k_c"
    std::string unit; ///< e.g. "N/m^(n+1)"
    double value = 0.0;
    double half_width_95 = 0.0; ///< [unit]
};

/// One fitted law: "bekker", "janosi", "mohr_coulomb_peak", "mohr_coulomb_residual", "repose".
struct LabFit {
    std::string law;
    int degrees_of_freedom = 0;
    std::vector<FittedValue> parameters;
};

/// One run of a test (one plate, one normal stress, the one lift): its condition and scalar
/// results, and its sampled curve as one column per quantity. Every name carries its unit.
struct LabRunSummary {
    std::vector<std::pair<std::string, double>> values;
    std::vector<std::pair<std::string, std::vector<double>>> curves;
    double value(const std::string &name) const; ///< throws std::out_of_range naming it
    const std::vector<double> &curve(const std::string &name) const; ///< the same
};

struct LabSummary {
    std::string test;      ///< "bevameter", "bevameter_shear", "direct_shear" or "repose"
    std::string scenario;  ///< the scenario's `name`
    std::string condition; ///< the run value that tells the runs apart, e.g. "plate_radius_m"
    LabBedSummary bed;
    std::vector<LabFit> fits; ///< the laws fitted; a law that could not be is left out ...
    std::string fit_note;     ///< ... and this says why (empty: every law fitted)
    std::vector<LabRunSummary> runs;
    double wall_s = 0.0; ///< [s] the whole test
    /// The fitted parameter `name` of `law`; throws std::out_of_range naming both.
    const FittedValue &fitted(const std::string &law, const std::string &name) const;
};

/// summary.json's text (format "grainlink-lab-summary", version 1). NaN (a repose test without
/// a heap) is written as null.
std::string toJson(const LabSummary &summary);
/// Reads summary.json's text; errors name `source` and what is wrong.
LabSummary labSummaryFromJson(const std::string &text, const std::string &source);

/// Writes toJson(summary) to `path`; throws naming the file when it cannot.
void writeLabSummary(const LabSummary &summary, const std::string &path);
LabSummary readLabSummary(const std::string &path);

} // namespace grainlink::lab
