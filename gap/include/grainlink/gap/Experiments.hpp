#pragma once
// Measured experiments: a folder with experiments.yaml and data files (docs/gap.md, "The
// measurements folder"). Each experiment is one test condition (a plate size in a box, a normal
// stress, a wheel at a slip angle) with its repeats, the columns and units of its data, the zero
// convention of its x axis and its measurement uncertainty. Everything is converted to SI on
// reading; the same zero convention is later applied to the simulated curves.
#include "grainlink/gap/Features.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

enum class ExperimentType {
    PlateSinkage,     ///< x sinkage [m] -> pressure [Pa]
    BevameterShear,   ///< x shear displacement [m] -> shear stress [Pa]
    DirectShear,      ///< x shear displacement [m] -> shear stress [Pa]
    AngleOfRepose,    ///< scalar angle [deg]
    WheelSteadyState, ///< x slip [-] -> drawbar pull / traction [N], sinkage [m], torque [N m], ...
    Mole,             ///< x stroke [-] -> depth [m]
};
const char *typeName(ExperimentType type);
/// Every experiment type, in the order of the enum.
std::vector<ExperimentType> experimentTypes();
ExperimentType parseType(const std::string &name); ///< throws std::invalid_argument
/// The observables an experiment of `type` may hold (SI names, e.g. "pressure_Pa").
const std::vector<std::string> &observablesOf(ExperimentType type);
/// "'pressure' is not an observable of plate_sinkage (its observables: pressure_Pa,
/// force_N)": every name an experiment of that type may give under data.y (a plate's force
/// among them), for the importer and experiments.yaml's reader alike.
std::string notAnObservable(const std::string &name, ExperimentType type);
/// Whether an experiment of that type may give `name` under data.y (a plate's force among
/// them): what notAnObservable lists.
bool isObservableOf(const std::string &name, ExperimentType type);
/// The SI name of its x ("sinkage_m", "slip"); "" for a scalar.
const char *xNameOf(ExperimentType type);

/// A condition given under another size's name, read as grainlink's: `plate_radius_m` as
/// `plate_diameter_m` (factor 2).
struct SizeAlias {
    const char *given, *name;
    double factor;
};
/// The conditions an experiment of a type may give: one table for experiments.yaml's reader,
/// the CSV importer and the simulation.
struct ConditionNames {
    /// What its test is set up from, besides `box`; any other is described, not simulated.
    std::vector<std::string> simulated;
    /// The one its test is run at experiment by experiment (a plate's size, a shear box's
    /// load), without which it cannot run; "" where the base's values stand in for every one.
    /// The others of `simulated` make its setup: experiments that share them run as one test.
    std::string per_experiment;
    std::vector<SizeAlias> aliases;
};
const ConditionNames &conditionsOf(ExperimentType type);
/// Conditions that describe an experiment of any type without setting up its test: its loading
/// speed (read by the rate check), its box and its bed's preparation (text naming which of the
/// base's soils it was).
const std::vector<std::string> &describingConditions();

/// The SI factor of a unit name ("kPa" -> 1000, "mm" -> 0.001, "deg" -> 1); throws naming the
/// unit when it is unknown or not of `dimension` ("length", "pressure", "force", ...).
double unitFactor(const std::string &unit, const std::string &dimension);

/// Where an experiment's x is zero.
struct ZeroConvention {
    enum class Method {
        AsRecorded,     ///< the data's own zero (e.g. a hand-picked first contact)
        FirstSample,    ///< x - x where the recording starts (its shallowest sample)
        ForceThreshold, ///< x - the least x at which y reaches `threshold` (SI)
    };
    Method method = Method::AsRecorded;
    double threshold = 0.0; ///< [SI unit of the experiment's first observable]
};

/// The measurement's own uncertainty (docs/gap.md, "Uncertainty of the measurement").
struct MeasurementUncertainty {
    double y_sigma = 0.0;      ///< [SI] standard uncertainty of one trial's level, independent between trials
    double y_relative = 0.0;   ///< [-] the same as a fraction of the value
    double y_systematic = 0.0; ///< [SI] common to every trial (a calibration)
    double x_zero_sigma = 0.0; ///< [SI of x] uncertainty of the x zero; enters as |dy/dx| sigma
    bool rebuilt_bed = true;   ///< repeats on re-prepared beds (their scatter holds the bed's)
    /// Its trials' beds served no other experiment (`beds: own`). Default (`shared`): trial t of
    /// every experiment of its type in its box was made on one bed t, as a twin's are, and
    /// the held-out test counts their luck as one (docs/gap.md, step 7).
    bool own_beds = false;
};

/// One trial: a curve per observable over the experiment's x (or one point of a scatter).
struct Trial {
    std::string source; ///< file (and row) it came from
    std::map<std::string, Curve> curves;
};

struct Experiment {
    std::string id;
    ExperimentType type = ExperimentType::PlateSinkage;
    std::string x_name = "sinkage_m";         ///< SI name of x; empty for a scalar
    std::vector<std::string> observables;     ///< SI names, e.g. "pressure_Pa"
    std::map<std::string, double> numbers;    ///< numeric conditions, SI (plate_diameter_m, ...)
    std::map<std::string, std::string> labels; ///< text conditions (box, preparation, ...)
    bool scatter = false; ///< each trial is one point (x, y): wheel tests, one row per run
    std::vector<Trial> trials;
    ZeroConvention zero;
    MeasurementUncertainty uncertainty;
    std::vector<double> bin_edges; ///< [SI of x] optional; empty: shared automatic bins
    std::string source;            ///< experiments.yaml:line
    /// "plate_sinkage/pressure_Pa": features of one kind are compared across experiments.
    std::string kind(const std::string &observable) const;
    /// Conditions as text, for the report and for localise().
    std::map<std::string, std::string> conditionText() const;
};

struct ExperimentSet {
    std::string name;
    std::string directory;
    std::vector<Experiment> experiments;
    /// What reading left out and why (samples missing a value), a line each, to be shown.
    std::vector<std::string> notes;
    const Experiment &find(const std::string &id) const;
};

/// A folder's own name, however it is written (`meas/`, `.`, `../meas`): a measurements set's
/// default name.
std::string folderName(const std::string &directory);

/// Reads DIR/experiments.yaml and every data file it names, strictly: an unknown key, a
/// missing column, a unit of the wrong kind or an unreadable file stops with the file, the key
/// and the line.
ExperimentSet loadExperiments(const std::string &directory);

/// A curve sorted by x with equal x merged (their mean), then shifted by the zero convention;
/// used for measured and simulated curves alike.
Curve applyZero(const Curve &curve, const ZeroConvention &zero);

/// How many samples of a curve in file order are its loading branch: all, unless it was
/// recorded in time order (x not falling at four in five steps up to its largest x) and then ran
/// back (an unloading, a retraction): then the samples up to its largest x. Reading a plate or
/// shear curve keeps only these.
std::size_t loadingBranch(const Curve &curve);

/// The SI dimension an observable's name implies by its unit suffix ("pressure_Pa" ->
/// "pressure", "sinkage_m" -> "length", "slip" -> "dimensionless").
std::string dimensionOf(const std::string &si_name);
/// The unit that suffix names ("pressure_Pa" -> "Pa", "torque_N_m" -> "N_m"); "" for none.
std::string unitOf(const std::string &si_name);

/// Turns a scatter of single points (x, y) into bin means: the feature for a scatter
/// experiment is the mean of the points in each bin.
std::vector<double> scatterBinMeans(const std::vector<std::pair<double, double>> &points,
                                    const std::vector<double> &edges, std::vector<int> &counts);

} // namespace grainlink::gap
