#pragma once
// The diagnosis (docs/gap.md, "The pipeline"): numerical uncertainty first, then where the gap
// lies, which catalogued effect explains it, and how far the gap on held-out experiments
// shrinks once the effect is added. What needs simulating is asked of a Simulator (DEM runs
// through `grainlink study`, or an analytic model in tests), in batches so that a study can
// run them in parallel and cache every one.
#include "grainlink/gap/Attribution.hpp"
#include "grainlink/gap/Comparison.hpp"
#include "grainlink/gap/Discrepancy.hpp"
#include "grainlink/gap/Effects.hpp"
#include "grainlink/gap/Validation.hpp"

#include <Eigen/Core>

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

/// One model variant to simulate: the base with up to two effects at given strengths, or with
/// one numerical choice changed (`check`), over seeds 0 .. seeds - 1 of the base's sequence.
struct VariantRequest {
    std::string label;
    const Effect *effect = nullptr;
    double strength = 0.0;
    const Effect *second = nullptr;
    double second_strength = 0.0;
    std::string check; ///< "", "resolution", "time_step", "domain", "rate"
    int seeds = 1;
    int seed_offset = 0; ///< the first seed: a twin's "measured" beds are not the model's own
    /// Each experiment on beds of its own (a twin of a test bed rebuilt for every trial), not
    /// every experiment of a group on the same bed per seed.
    bool own_beds = false;
};

/// Runs variants of the base model on a design: one matrix per request, seeds x features.
class Simulator {
public:
    virtual ~Simulator() = default;
    /// The numerical checks this simulator can run ("resolution", ...).
    virtual std::vector<std::string> checks() const = 0;
    virtual std::vector<Eigen::MatrixXd> simulate(const ExperimentSet &design,
                                                  const FeatureDesign &features,
                                                  const std::vector<VariantRequest> &requests) = 0;
    /// Experiments that could be added to `design` (conditions only, no data): a plate test,
    /// a direct shear test, an angle of repose, ...; used to name the experiment that would
    /// separate effects the design cannot tell apart. Empty: none offered.
    virtual std::vector<ExperimentSet> probes(const ExperimentSet &design) const {
        (void)design;
        return {};
    }
    /// The scenario effects are resolved against (their off values, their applicability).
    virtual YAML::Node referenceScenario() const = 0;
    /// Why `request` cannot run on `design` (a scenario that does not validate: a variant
    /// coarsening the grains below a plate's resolution); "" where it can. Runs nothing.
    virtual std::string refusal(const ExperimentSet &design, const VariantRequest &request) const {
        (void)design;
        (void)request;
        return "";
    }
    /// The simulations `request` makes on `design`, by their cache ids: two requests with the
    /// same ids run the same scenarios. Empty where the simulator cannot tell.
    virtual std::vector<std::string> runIds(const ExperimentSet &design,
                                            const VariantRequest &request) const {
        (void)design;
        (void)request;
        return {};
    }
    /// Experiments the simulator runs on the same beds (a seed's one packing) share a group:
    /// held-out evidence is counted per group, since the model's error from its few beds is
    /// shared by every experiment in them. Default: each experiment its own beds.
    virtual std::string bedGroup(const Experiment &experiment) const { return experiment.id; }
};

struct DiagnosisOptions {
    double alpha = 0.05;   ///< family-wise level of the gap test and of each claim
    double flag_at = 2.0;  ///< a feature beyond this many u_val is flagged
    int seeds = 3;         ///< base and confirming runs
    int signature_seeds = 2;
    int check_seeds = 3; ///< two pairs give a one-feature experiment one dof (docs/gap.md, step 2)
    int measurement_grid = 17; ///< strengths tabulated for a measuring-chain effect (no simulation)
    int max_confirmed = 3;    ///< candidates re-simulated at their fitted strength
    int pair_pool = 4;        ///< singles combined into pairs when none explains the gap
    /// A confirmed effect whose kinds of observable ask for strengths that disagree at this
    /// level (`strengthAgreement`) absorbs a difference of model form: never claimed.
    double agreement_level = 0.01;
    /// Held-out experiments by id; empty: the split rule of docs/gap.md ("Calibration and
    /// held-out experiments").
    std::vector<std::string> held_out;
    std::function<void(const std::string &)> log; ///< progress lines
};

/// What the diagnosis found about one candidate effect.
struct CandidateResult {
    std::string name;
    std::string applicability; ///< empty: applicable; else why not
    Effect effect;             ///< resolved against the base
    StrengthFit fit;           ///< on the calibration features
    /// chi^2 of the fit on the signatures alone, which ranks the candidates and chose those
    /// re-simulated (`fit.chi2` is refitted once a confirming run joins the table)
    double ranking_chi2 = 0.0;
    double signature_chi2 = 0.0; ///< its largest simulated change of the design, in chi^2 (u_val);
                                 ///< below 1 the effect does not act on these experiments
    /// Whether its strongest simulated change moves the design by a unit of u_val or more: one
    /// that does not can explain no gap here, and is neither confirmed nor named closest.
    bool actsOnDesign() const { return signature_chi2 >= 1.0; }
    double calibration_gain = 0.0; ///< chi^2 with the effect off minus at its best strength
    HeldOutScore predicted;    ///< held-out score from the signature (before confirmation)
    bool confirmed = false;    ///< re-simulated at the fitted strength
    HeldOutScore held_out;     ///< held-out score of the confirming simulation
    DensityComparison versus_null; ///< sample-split test against the null (held-out)
    bool beats_null = false;
    bool explains = false;     ///< beats the null and leaves no gap on any feature
    GapVerdict after;          ///< the gap test with the effect added (confirmed)
    /// The strength each kind of observable asks for alone, over every compared experiment,
    /// with the beds' luck (confirmed candidates; "plate_sinkage/pressure_Pa" -> its fit), and
    /// whether they agree.
    std::vector<std::pair<std::string, StrengthFit>> by_kind;
    StrengthAgreement agreement;
    bool strengths_agree = true;    ///< the agreement's p is at the options' level or above
    Eigen::VectorXd confirmed_mean; ///< features of the confirming runs
    Eigen::VectorXd confirmed_z;    ///< their normal-equivalent residuals, as `after` judged them
};

struct PairResult {
    std::string a, b;
    PairFit fit;
    bool confirmed = false;
    HeldOutScore held_out;
    DensityComparison versus_null;
    bool beats_null = false; ///< predicts the held-out experiments better, at the pairs' level
    bool explains = false;
    GapVerdict after;
    Eigen::VectorXd confirmed_mean;
    Eigen::VectorXd confirmed_z;
    /// p of the best pair (the best held-out prediction without a gap) predicting the held-out
    /// experiments better than this one; NaN for the best itself, a pair with a gap, or one
    /// not confirmed.
    double best_over_it_p = std::numeric_limits<double>::quiet_NaN();
    /// Each strength by kind of observable, the other held at its fit (as a single's
    /// `by_kind`), and whether they agree: both must.
    std::vector<std::pair<std::string, StrengthFit>> a_by_kind, b_by_kind;
    StrengthAgreement a_agreement, b_agreement;
    bool strengths_agree = true;
};

struct Diagnosis {
    FeatureDesign design;
    Measured measured;
    ValidationResult validation;
    GapVerdict verdict;
    std::vector<RegimeFinding> findings;
    std::vector<Eigen::Index> calibration, held_out; ///< feature indices
    std::vector<std::string> calibration_experiments, held_out_experiments;
    /// Experiments with no simulated feature to compare (their runs failed or fell short):
    /// named in the claim, never counted as agreeing.
    std::vector<std::string> not_compared;
    /// Experiments compared in some measured bins only ("id (k of n measured bins)"): named too.
    std::vector<std::string> partly_compared;
    HeldOutScore held_out_base;  ///< the base model on the held-out features
    HeldOutScore held_out_null;  ///< base + the fitted discrepancy
    Eigen::VectorXd null_mean, null_variance; ///< the null model's prediction (held-out features)
    std::vector<CandidateResult> candidates; ///< ranked by calibration chi^2 (applicable first)
    std::vector<PairResult> pairs;
    /// Signature overlap on the whole design: overlap[i][j] = how much of candidate i's
    /// signature candidate j reproduces (candidates in `candidates` order; applicable ones).
    std::vector<std::vector<double>> overlap;
    /// A claim's rivals: other confirmed candidates that leave no held-out gap (at their
    /// prior's edge too, and whether or not they beat the null), each with the p of the claimed
    /// model predicting the held-out experiments better than it (the test against the null,
    /// the rival as null).
    struct Rival {
        std::string name;
        double p_value = 1.0;
        bool at_prior_edge = false;
        bool beats_null = true;
    };
    std::vector<Rival> rivals;
    std::vector<std::string> indistinguishable; ///< candidates the design cannot tell from the leader
    std::string separating_experiment;         ///< the probe that would separate them best
    /// Where in that probe they differ most (`FeatureKey::label`), and what each predicts
    /// there: the base first, then the leader and the others at their fitted strengths.
    struct ProbePrediction {
        std::string model;    ///< "base" or the effect's name
        std::string strength; ///< the fitted strength it ran at, in words ("" for the base)
        double mean = 0.0, sd = 0.0; ///< over the probe's seeds; sd: the mean's
        std::string label() const { return strength.empty() ? model : model + " (" + strength + ")"; }
    };
    std::string separating_feature;
    std::vector<ProbePrediction> separating_predictions;
    /// The probe's separation: sum over features and pairs of candidates of d^2 over their
    /// variance and the base's (an expected chi^2 between them on one run of the probe).
    double separating_chi2 = 0.0;
    /// Unresolved: no gap is found, but only because a numerical check of the base model moves
    /// the simulation by more than half its value: nothing can be said until it is refined.
    enum class Outcome { NoGap, Explained, ExplainedByPair, Unexplained, Unresolved };
    Outcome outcome = Outcome::NoGap;
    /// Non-empty when a numerical check moves the base's features by a median of more than
    /// half their value (the check and the figure), or failed on every run of an experiment,
    /// whatever the outcome.
    std::string numerical_warning;
    /// The model the claim names: the winning effect, the explaining pair ("a + b"), or the
    /// closest confirmed candidate when unexplained (empty when nothing was confirmed).
    std::string best_model;
    Eigen::VectorXd best_model_mean; ///< its confirming runs' features (empty with no model)
    Eigen::VectorXd best_model_z;    ///< their residuals as its gap test judged them
    std::string explained_by; ///< best_model when the outcome is an explanation, else empty
    /// Unexplained: the confirmed candidate nearest to a claim by its p value against the null,
    /// when that is not best_model (the closest by held-out gap); else empty.
    std::string nearest_to_claim;
    std::string claim;        ///< one sentence: the result (and what was not compared)
    std::string unexplained;  ///< what remains (features still flagged after the best model)
    /// The runs asked for, each once (cached runs reused): a variant on a seed, over a group of
    /// experiments on one bed where the simulator runs them so.
    int simulations = 0;
    /// Variants answered by a run already asked for: the measuring chain's variants read the
    /// runs of the base or of an effect of the soil (a zero offset reruns nothing).
    int reads = 0;
    /// The levels a confirmed single and a confirmed pair are tested at against the null:
    /// alpha over the singles whose confirming runs ran (and the pairs confirmed); 0 when
    /// nothing was confirmed.
    double single_level = 0.0, pair_level = 0.0;
};
const char *outcomeName(Diagnosis::Outcome outcome);

/// Where a confirmed candidate stands, in words: "explains", or why it is not claimed ("does
/// not beat the null model", "beats the null model but leaves a gap", ...).
std::string standing(const CandidateResult &c);

/// The confirmed candidate (or pair) that predicts the held-out experiments best (log density)
/// among those that leave no gap: the one a claim may go to, and only if it explains; where it
/// does not, the others that explain are not told apart from it and nothing is claimed. Null
/// where none leaves no gap.
template <class Model> const Model *bestWithoutGap(const std::vector<Model> &models);

/// The confirmed candidate or pair that `best_model` names, with each of its effects and
/// fitted strengths, its held-out score and test, and the level it was judged at; neither
/// (null pointers) when nothing confirmed is named.
struct NamedModel {
    const CandidateResult *single = nullptr;
    const PairResult *pair = nullptr;
    std::vector<std::pair<const Effect *, StrengthFit>> strengths;
    const HeldOutScore *held_out = nullptr;
    const DensityComparison *versus_null = nullptr;
    double level = 0.0;
};
NamedModel namedModel(const Diagnosis &d);

/// The verdict in one fixed form, the first line of the report: the outcome in capitals; the
/// model it names (claimed, or the closest when unexplained) with each strength and its 95 %
/// interval; the held-out gap with the base, with the model and with the null model; p against
/// the level. `claim` says the same at length, with what it rests on.
std::string headline(const Diagnosis &d);

/// When nothing is claimed, two confirmed candidates come closest: the one whose added effect
/// leaves the smallest held-out gap (of equal gaps, the best held-out density), and the one
/// nearest to a claim (the smallest p against the
/// null). Either is null when nothing was confirmed; they may be the same. Without held-out
/// experiments (one experiment) there is nothing to predict: `by_gap` is then the candidate
/// that fits the calibration experiments best (the smallest chi^2), confirmed or not.
struct ClosestCandidates {
    const CandidateResult *by_gap = nullptr;
    const CandidateResult *by_p_value = nullptr;
};
ClosestCandidates closestCandidates(const std::vector<CandidateResult> &candidates,
                                    bool held_out_exists = true);

/// The calibration / held-out split by experiment id (docs/gap.md): `held_out` when given;
/// otherwise, for every experiment type with two or more experiments, the experiments of its
/// last condition group (its last `box` label when it has several, else its last half, rounded
/// down).
std::vector<std::string> defaultHeldOut(const ExperimentSet &set);

/// The held-out experiments of a diagnosis: `opt.held_out`, each checked to exist, or else
/// `defaultHeldOut`.
std::vector<std::string> heldOutIds(const ExperimentSet &set, const DiagnosisOptions &opt);

/// What the split leaves thin, in words: each type calibrated on a single experiment while
/// two or more of it are held out (its strengths then rest on that one experiment).
std::vector<std::string> splitNotes(const ExperimentSet &set,
                                    const std::vector<std::string> &held_out);

/// What a diagnosis will simulate before its first result, worked out without simulating
/// (`grainlink gap diagnose --dry-run`): its features, its split, the base's runs and numerical
/// checks, and every applicable effect's signature runs (needed once a gap shows).
struct DiagnosisPlan {
    FeatureDesign design;
    Measured measured;
    std::vector<std::string> held_out;      ///< experiment ids
    std::vector<VariantRequest> first;      ///< the base and its numerical checks
    std::vector<VariantRequest> signatures; ///< every applicable effect's strengths
    std::vector<std::string> applicable;    ///< effect names
    std::vector<std::pair<std::string, std::string>> inapplicable; ///< effect, why not
    /// Proposed experiments (Simulator::probes) the base cannot run: probe, why not. The
    /// diagnosis leaves them out of its proposal.
    std::vector<std::pair<std::string, std::string>> probes_refused;
};
DiagnosisPlan planDiagnosis(const ExperimentSet &set, const std::vector<const Effect *> &effects,
                            const Simulator &simulator, const DiagnosisOptions &opt);

/// Runs the whole pipeline on measured `set` with the catalogue's diagnosable `effects`.
Diagnosis diagnose(const ExperimentSet &set, const std::vector<const Effect *> &effects,
                   Simulator &simulator, const DiagnosisOptions &options);

/// How well a probe's runs (`rows[0]` the base's, then one per candidate, each seeds x
/// features) tell the candidates apart: per feature, the sum over pairs of candidates of
/// their means' squared difference over the two means' variances and the base mean's, every
/// variance from one bed's scatter pooled over all the rows (so two seeds of at least one
/// model are needed: without them nothing is known to separate, and chi2 is 0).
struct ProbeSeparation {
    Eigen::VectorXd chi2;
    std::vector<Eigen::VectorXd> mean, sd; ///< per row: its mean and that mean's sd
};
ProbeSeparation probeSeparation(const std::vector<Eigen::MatrixXd> &rows);

} // namespace grainlink::gap
