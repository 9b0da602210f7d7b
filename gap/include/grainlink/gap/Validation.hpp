#pragma once
// Numerical uncertainty first (ASME V&V 20): the validation uncertainty u_val of every feature
// from the simulation's bed realisations, its numerical checks (resolution, time step, domain,
// loading rate) and the measurement, then the standardised residuals, the gap test and the
// words that say where the gap lies (docs/gap.md, "Validation uncertainty").
#include "grainlink/gap/Features.hpp"

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// The measured side of every feature.
struct Measured {
    std::vector<FeatureKey> keys;
    Eigen::VectorXd value; ///< mean over the trials
    Eigen::VectorXd u_D;   ///< standard uncertainty of that mean: repeats, stated sigma, zero
    Eigen::VectorXd u_repeats; ///< the part of u_D estimated from the repeats' scatter
    Eigen::VectorXi trials;
    /// Each trial's own value (rows: the experiments' trials in order; NaN where a trial has
    /// no value in the bin, and for scatter data, whose points are no trials).
    Eigen::MatrixXd trial_values;
    /// True where u_D comes from repeats on re-prepared beds (and so holds the bed-to-bed
    /// scatter); where false the simulation's single-bed scatter is added (one real bed is one
    /// realisation too).
    std::vector<bool> from_repeats;
    std::size_t size() const { return keys.size(); }
};

/// One numerical check: the same features simulated with one numerical choice changed.
struct NumericalCheck {
    std::string name;     ///< "resolution", "time_step", "domain", "rate"
    Eigen::MatrixXd rows; ///< seeds x features
};

/// The part of every predictive variance that is estimated from few samples, per feature, with
/// its degrees of freedom: the measured mean's scatter from its repeats (trials - 1) and, where
/// there are no repeats on rebuilt beds, one simulated bed's (seeds - 1). A held-out feature's
/// density is then Student's t of the Welch-Satterthwaite degrees of freedom of its predictive
/// variance, as a residual over a variance estimated so is distributed: scored as normal, a
/// sharp model is charged r^2 / s^2, whose mean is infinite when s^2 has two degrees of freedom
/// (three repeats), and one bin whose repeats happen to agree outweighs the rest.
/// Empty: every variance is exact (normal densities).
struct EstimatedVariance {
    Eigen::VectorXd variance, dof;
    /// Degrees of freedom of a predictive variance v holding feature k's estimated part.
    double dofOf(Eigen::Index k, double v) const;
};

/// Every part of u_val, per feature, and the residuals it standardises.
struct ValidationResult {
    Eigen::VectorXd simulated;  ///< base mean over seeds
    Eigen::VectorXd seed_sd;    ///< scatter of one bed realisation (sd over seeds)
    Eigen::VectorXd u_seed;     ///< seed_sd / sqrt(seeds): the simulated mean's own scatter
    Eigen::VectorXd u_bed;      ///< seed_sd where the measurement has no repeats, else 0
    std::vector<std::pair<std::string, Eigen::VectorXd>> u_checks; ///< systematic part per check
    /// (check, experiment) where every run of the check failed: its part of u_num there is
    /// unknown (counted as 0, so u_val is too small there, never too large).
    std::vector<std::pair<std::string, std::string>> check_failures;
    Eigen::VectorXd u_num;      ///< sqrt(u_seed^2 + sum u_check^2)
    Eigen::VectorXd u_D;        ///< measurement
    Eigen::VectorXd u_val;      ///< sqrt(u_num^2 + u_bed^2 + u_D^2)
    Eigen::VectorXd residual;   ///< measured - simulated
    Eigen::VectorXd standardised; ///< residual / u_val
    /// Degrees of freedom of u_val (Welch-Satterthwaite: the seeds' and repeats' scatter are
    /// estimates from few samples; stated uncertainties and checks count as exact).
    Eigen::VectorXd dof;
    /// The parts of a prediction's variance estimated from few samples (the repeats' scatter,
    /// one simulated bed's where there are no repeats): what the held-out densities read.
    EstimatedVariance estimated;
    /// The standardised residual as the normal deviate of the same tail probability under
    /// Student's t with `dof`: what the gap test and the flags use.
    Eigen::VectorXd z;
    Eigen::VectorXd ratio;      ///< simulated / measured
};

/// The normal deviate with the same two-sided tail probability as `t` under Student's t with
/// `dof` degrees of freedom (infinite or NaN dof: t itself).
double normalEquivalent(double t, double dof);

/// u_val and the residuals of `base` (seeds x features) against `measured`. A check's
/// systematic part is, per experiment, its mean relative difference from the base over the
/// experiment's features with the seed noise of that mean removed in quadrature,
/// u_k = |base| sqrt(max(0, mean_r^2 - var mean_r)). Throws if the shapes differ.
ValidationResult validate(const Measured &measured, const Eigen::MatrixXd &base,
                          const std::vector<NumericalCheck> &checks);

/// The numerical check that moves the base's features most, in words, when it moves them by a
/// median of more than half their value: a base model not resolved in that choice, against
/// which no comparison means anything (a soil stepped near its stability limit pressed the
/// plates tenfold softer at twice the time step). Empty when every check is below that.
std::string unresolvedCheck(const ValidationResult &validation);

/// The parts of u_val, each as the median over features of its size relative to the simulated
/// value (V&V 20's budget): the measurement, the beds without repeats, the simulated mean's
/// seeds, then each numerical check by name, then u_val itself. Says which choice of the base
/// model would pay most to refine.
std::vector<std::pair<std::string, double>> uncertaintyBudget(const ValidationResult &validation);

/// Everything to warn about the numerical uncertainty, in words: the unresolved check above and
/// the experiments where a check's runs all failed. Empty when there is nothing.
std::string numericalWarning(const ValidationResult &validation);

/// The gap test, three tests each at a third of the family-wise level alpha, valid whatever the
/// correlation between an experiment's features (experiments independent): (a) some |z| above
/// the Bonferroni bound over all features; (b) some experiment's root-mean-square z above the
/// Bonferroni bound over experiments (a consistent gap of moderate size); (c) the sum over
/// experiments of their mean z^2 above the chi^2 quantile with one degree of freedom per
/// experiment (many features moderately off: a mean of correlated z^2 spreads at most like one
/// z^2). A feature beyond `flag_at` (2 u_val) is flagged either way.
struct GapVerdict {
    bool gap = false;
    /// (a) the feature nearest its kind's bound (each kind of observable holds alpha/3 over the
    /// number of kinds, shared among its features): its |e|, that bound and its kind
    double max_abs = 0.0, feature_bound = 0.0;
    std::string worst_kind;
    std::string worst_experiment;
    double worst_rms = 0.0, experiment_bound = 0.0;
    double sum_mean_square = 0.0, sum_bound = 0.0; ///< (c)
    int flagged = 0, features = 0;
    std::string summary; ///< one sentence
};
GapVerdict testGap(const std::vector<FeatureKey> &keys, const Eigen::VectorXd &standardised,
                   double alpha = 0.05, double flag_at = 2.0);

/// Two-sided standard normal quantile bound: |z| exceeded with probability p.
double normalBound(double p);

/// Where the gap lies, in words: for each kind, the x-ranges where the experiments agree that
/// the simulation is too high or too low (beyond `flag_at` u_val), with the range of the
/// simulated/measured ratio, the experiments concerned (named by a condition they alone share
/// when there is one), and the ranges within uncertainty.
struct RegimeFinding {
    std::string kind;
    double x_lo = 0.0, x_hi = 0.0;
    int sign = 0;          ///< +1 simulation too high, -1 too low, 0 within uncertainty
    int experiments = 0;   ///< flagged with this sign
    int covering = 0;      ///< experiments with a feature in this range
    double ratio_min = 0.0, ratio_max = 0.0;
    std::string text;
};
using Conditions = std::map<std::string, std::string>;
/// How a kind's x axis is written: "sinkage", "mm", 1000 (x is in m).
struct AxisLabel {
    std::string name, unit;
    double scale = 1.0;
};
std::vector<RegimeFinding> localise(const std::vector<FeatureKey> &keys,
                                    const ValidationResult &validation,
                                    const std::map<std::string, Conditions> &conditions,
                                    const std::map<std::string, AxisLabel> &axes,
                                    double flag_at = 2.0);

} // namespace grainlink::gap
