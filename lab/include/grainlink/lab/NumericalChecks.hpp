#pragma once
// Numerical checks of a lab test (docs/lab.md, physics.md §12.14): the test reruns itself on a
// wider box (wall effects) or on finer grains (resolution), and the report says how far each
// answer moved. The moves are the test's numerical uncertainty.
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/Bevameter.hpp"
#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/lab/Repose.hpp"

#include <Eigen/Core>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

enum class CheckKind {
    Walls,     ///< region and side walls widened in x and y about the region centre
    Resolution ///< every grain radius scaled by a factor < 1
};
std::string checkName(CheckKind kind); ///< "walls" or "resolution"

/// The soil widened by `factor` > 1 in x and y about `about_m` (unset: the centre of the
/// deposition region): the region, every wall plane (points mapped, normals by the inverse
/// transpose) and the grain count (times factor^2, so the settled bed keeps its depth). Heights,
/// grains and contact law stay.
dem::DemScenario widenedSoil(const dem::DemScenario &soil, double factor,
                             const std::optional<Eigen::Vector2d> &about_m = std::nullopt);

/// The soil with every grain radius scaled by `factor` in (0, 1) and the contact law scaled so
/// that grains of the new size behave as the old ones did (physics.md §12.14): count / factor^3
/// (same solid volume), time step, linear tangential stiffness and neighbour skin times factor,
/// viscous dampers times factor^2, the settling energy per grain times factor^3.
dem::DemScenario refinedSoil(const dem::DemScenario &soil, double factor);

/// The soil changed for one check.
dem::DemScenario checkedSoil(const dem::DemScenario &soil, CheckKind kind, double factor);

/// One answer of a test, as the baseline and a rerun gave it.
struct CheckedQuantity {
    std::string name; ///< e.g. "p(10 mm), R = 25 mm"
    std::string unit; ///< e.g. "Pa"
    double value = 0.0;
};
using Quantities = std::vector<CheckedQuantity>;

struct CheckComparison {
    std::string name, unit;
    double baseline = 0.0, rerun = 0.0;
    double difference() const { return rerun - baseline; }
    double relativeDifference() const; ///< difference / |baseline|; NaN for a zero baseline
};

struct NumericalCheck {
    CheckKind kind = CheckKind::Walls;
    double factor = 1.0;
    std::string change; ///< what the rerun changed, in words
    std::vector<CheckComparison> comparisons;
    double wall_s = 0.0; ///< of the rerun
};

/// Which reruns a lab test does, and by how much.
struct CheckRequest {
    bool walls = false;
    bool resolution = false;
    double widen_factor = 2.0;   ///< box width times this (> 1)
    double radius_factor = 0.75; ///< grain radii times this (< 1)
    bool any() const { return walls || resolution; }
    void validate() const; ///< throws std::invalid_argument naming the factor
};

/// Parses the command line's `--check walls|resolution|both` with an optional `--check-factor`
/// (the factor of that check; not allowed with `both`, which takes both defaults).
CheckRequest parseCheckRequest(const std::string &check, double factor);

/// A rerun's options: the baseline's, writing into options.output_directory/check_<name>.
LabRunOptions checkRunOptions(const LabRunOptions &options, const std::string &name);

/// Reruns a test for every requested check and compares its quantities with the baseline's.
/// `rerun(kind, factor, directory_name)` runs the test on the changed scenario (use
/// checkedSoil for its soil, plus whatever the test's own geometry needs) and returns the same
/// quantities, by name, as `baseline`; a name missing from the rerun is an error.
std::vector<NumericalCheck> runNumericalChecks(
    const CheckRequest &request, const Quantities &baseline,
    const std::function<Quantities(CheckKind kind, double factor, const std::string &name)> &rerun);

/// "baseline vs rerun" table of every check, for report.txt.
std::string describeNumericalChecks(const std::vector<NumericalCheck> &checks);

/// Writes `directory`/numerical_check.csv (check, factor, quantity, unit, baseline, rerun,
/// difference, relative_difference) and appends describeNumericalChecks to report.txt.
void writeNumericalChecks(const std::vector<NumericalCheck> &checks, const std::string &directory);

// ---- the checks of the lab tests ------------------------------------------------------------

/// Bevameter answers: p at 1/4, 1/2, 3/4 and all of max_sinkage_m per plate (interpolated in the
/// samples) and Bekker's k_c, k_phi, n when the result has a fit.
Quantities bevameterQuantities(const BevameterResult &result, double max_sinkage_m);
/// Reruns the bevameter (outputs in options.output_directory/check_<name>) and compares.
std::vector<NumericalCheck> checkBevameter(const BevameterScenario &scenario,
                                           const BevameterResult &baseline,
                                           const CheckRequest &request,
                                           const LabRunOptions &options);

/// Repose answers: the angle (not the heap height, which the widened fill changes by design).
Quantities reposeQuantities(const ReposeResult &result);
/// Reruns the repose test (the widened one with its tube radius widened too) and compares.
std::vector<NumericalCheck> checkRepose(const ReposeScenario &scenario,
                                        const ReposeResult &baseline, const CheckRequest &request,
                                        const LabRunOptions &options);

/// Direct shear answers: psi and c of the peak and of the residual Mohr-Coulomb fits (those
/// that exist) and the bed's packing fraction.
Quantities directShearQuantities(const DirectShearResult &result);
/// Reruns the direct shear test. Walls: the box's length and width x F (the soil widened about
/// the box corner (0, 0)), the servo gain / F^2 and its deadband x F^2 (the bed's stiffness
/// under the plate grows with its area, so gain x stiffness x interval stays). Resolution: the
/// servo is kept (the bed's stiffness E A / H does not depend on the grain size).
std::vector<NumericalCheck> checkDirectShear(const DirectShearScenario &scenario,
                                             const DirectShearResult &baseline,
                                             const CheckRequest &request,
                                             const LabRunOptions &options);

} // namespace grainlink::lab
