#pragma once
// The diagnosis' simulations as grainlink runs (docs/gap.md, "The base model"): every
// experiment becomes a lab test of the base model (a plate test, a direct shear box, an angle
// of repose, a bevameter shear annulus, a wheel) or a coupled run (the HP3 mole) with its
// conditions filled in; experiments that share a
// bed run in one test (plates of several sizes on copies of one settled bed). Each variant x
// seed x test is one point of a `grainlink study`, cached by its resolved scenario, so a killed
// diagnosis resumes without redoing finished runs and the same run is never made twice.
#include "grainlink/gap/Diagnosis.hpp"
#include "grainlink/study/Study.hpp"

#include <yaml-cpp/yaml.h>

#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// The base model file (docs/gap.md): the soil, how each experiment type is simulated, the
/// simulated container per measured box, and the numerical uncertainty plan.
struct BaseModel {
    std::string path;
    std::string name;
    YAML::Node soil;                           ///< the DEM soil (docs/scenario.md)
    std::map<std::string, YAML::Node> tests;   ///< experiment type -> {<lab section>: ..., soil: ...}
    /// text condition -> its value -> the soil merged over the base's for experiments with it
    /// (`boxes:` gives the `box` condition's, `conditions:` any other's: a bed preparation)
    std::map<std::string, std::map<std::string, YAML::Node>> conditions;
    int seeds = 3, signature_seeds = 2, check_seeds = 3, threads = 1;
    std::map<std::string, double> checks;      ///< numerical check -> its factor
};

/// Reads the base model strictly (unknown keys with file:line); the soil and test sections are
/// checked by the lab's own readers on every scenario made from them.
BaseModel loadBaseModel(const std::string &path);

/// The experiments of `set` whose type the base model simulates (it has `tests.<type>`); the
/// others' ids with why go to `left_out` (e.g. a folder of plates and wheels diagnosed with a
/// plates-only base).
ExperimentSet simulable(const ExperimentSet &set, const BaseModel &base,
                        std::vector<std::string> &left_out);

/// Where an experiment states its loading speed (`speed_m_s`) and its test is simulated at
/// another (by more than 10 %), the base's numerical checks get the loading rate check
/// (`rate`, factor 0.5) when they lack it: the simulated rate is not the measured one, so its
/// effect belongs in the numerical uncertainty (docs/gap.md, step 2). Returns a note naming
/// the experiments and both speeds; empty when nothing was added.
std::string addRateCheckWhereSpeedDiffers(BaseModel &base, const ExperimentSet &set);

/// The section of the base's `tests.<type>` that sets up an experiment type's simulation: its
/// lab test's ("bevameter", "direct_shear", ...), or "mole" (the HP3 mole of a coupled run).
std::string testSectionOf(ExperimentType type);

class StudySimulator final : public Simulator {
public:
    /// `directory`: the study folder every run goes into (shared by every diagnosis and twin
    /// that uses it: the cache).
    StudySimulator(BaseModel base, std::string directory, study::ExecutorOptions executor);

    std::vector<std::string> checks() const override;
    std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &design,
                                          const FeatureDesign &features,
                                          const std::vector<VariantRequest> &requests) override;
    std::vector<ExperimentSet> probes(const ExperimentSet &design) const override;
    YAML::Node referenceScenario() const override;
    std::string refusal(const ExperimentSet &design, const VariantRequest &request) const override;
    std::vector<std::string> runIds(const ExperimentSet &design,
                                    const VariantRequest &request) const override;
    /// One type in one box: its runs at one seed share one cached packing.
    std::string bedGroup(const Experiment &experiment) const override;

    /// The simulated curves of one variant and seed (measurement effects applied), per
    /// experiment; what `simulate` turns into features.
    std::vector<SimulatedCurves> curves(const ExperimentSet &design,
                                        const std::vector<VariantRequest> &requests,
                                        std::vector<int> &seeds_of);

    /// The resolved scenario of one test group for one variant and seed (YAML text), as a
    /// study point runs it.
    std::string scenarioText(const ExperimentSet &design, const std::vector<std::string> &group,
                             const VariantRequest &request, int seed) const;

    /// The experiments that run as one lab test: one type in one box (wheels: one wheel under
    /// one load); each experiment alone where any request asks for beds of its own.
    std::vector<std::vector<std::string>>
    groups(const ExperimentSet &design, const std::vector<VariantRequest> &requests = {}) const;

    /// The lab's warnings on the base's tests (a direct shear box under ten grains across),
    /// each at the base's line that wrote the key: to be said before anything runs.
    const std::vector<std::string> &labWarnings() const { return lab_warnings_; }
    /// Prints them to stderr, one `[gap] base: ...` line each.
    void sayLabWarnings() const;

    int runsDone() const { return runs_done_; }
    int runsReused() const { return runs_reused_; }

    /// The runs `requests` would need (equal scenarios once), each validated as a study point
    /// is before it runs, and how many the cache holds finished or failed. Runs nothing.
    struct RunCount {
        std::size_t runs = 0, done = 0, failed = 0;
    };
    RunCount plan(const ExperimentSet &design, const std::vector<VariantRequest> &requests) const;

private:
    /// A study's error `what` with where the base file wrote the key it names, if it does.
    std::string withBaseLine(const std::string &what) const;
    /// Where one (request, seed, test group) runs: a point of the study.
    struct Slot {
        std::size_t request;
        int seed;
        std::size_t group;
        std::size_t point;
    };
    /// The study of every (request, seed, test group of `groups`), equal scenarios one point;
    /// `slots` says which.
    study::Study studyOf(const ExperimentSet &design,
                         const std::vector<std::vector<std::string>> &groups,
                         const std::vector<VariantRequest> &requests,
                         std::vector<Slot> &slots) const;
    struct Overlay {
        std::string condition, value;
        YAML::Node soil;
    };
    /// The soils the base gives for the experiment's text conditions, its box's first.
    std::vector<Overlay> overlaysOf(const Experiment &e) const;
    YAML::Node scenarioNode(const ExperimentSet &design, const std::vector<std::string> &group,
                            const VariantRequest &request, int seed) const;
    void collectLabWarnings();
    BaseModel base_;
    std::string directory_;
    study::ExecutorOptions executor_;
    int runs_done_ = 0, runs_reused_ = 0;
    std::vector<std::string> lab_warnings_;
};

} // namespace grainlink::gap
