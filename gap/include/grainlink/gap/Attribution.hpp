#pragma once
// Attribution: how each candidate effect changes the features with its strength (its
// response, from simulated signatures or from a transform of the base curves), the strength
// that best explains the calibration experiments, how far two effects' signatures overlap on
// the design, and how well a fitted model predicts the held-out experiments against the null
// (docs/gap.md, "Attribution" and "Confirmation").
#include "grainlink/gap/Correlation.hpp"
#include "grainlink/gap/Features.hpp"
#include "grainlink/gap/Validation.hpp"

#include <Eigen/Core>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// An effect's strength parameter: its prior range, the value that switches it off (the base
/// model), and whether it acts on a logarithmic scale (a stiffness factor).
struct Prior {
    double lo = 0.0, hi = 1.0;
    double off = 0.0;
    bool log_scale = false;
    double toScale(double s) const;   ///< s or log s
    double fromScale(double t) const; ///< the inverse
    bool contains(double s) const { return s >= lo && s <= hi; }
};

/// The simulated features with an effect at strength s: their mean and that mean's variance
/// (seed noise).
class Response {
public:
    virtual ~Response() = default;
    virtual Eigen::VectorXd mean(double s) const = 0;
    virtual Eigen::VectorXd variance(double s) const = 0;
};

/// A response simulated at a few strengths (the off value among them) and interpolated
/// piecewise linearly on the prior's scale; beyond the outermost strengths the last segment is
/// extended (only as far as the prior allows).
class TabulatedResponse final : public Response {
public:
    TabulatedResponse(const Prior &prior, std::vector<double> strengths,
                      std::vector<Eigen::VectorXd> means, std::vector<Eigen::VectorXd> variances);
    Eigen::VectorXd mean(double s) const override;
    Eigen::VectorXd variance(double s) const override;
    const std::vector<double> &strengths() const { return strengths_; }
    /// Adds a simulated strength (a confirming run), keeping the table sorted.
    void add(double s, const Eigen::VectorXd &mean, const Eigen::VectorXd &variance);

private:
    Eigen::VectorXd interpolate(const std::vector<Eigen::VectorXd> &table, double s) const;
    Prior prior_;
    std::vector<double> strengths_;
    std::vector<Eigen::VectorXd> means_, variances_;
};

/// A response computed exactly for any strength (an effect of the measuring chain, applied to
/// the simulated base curves: a sensor zero offset, a compliant rig).
class FunctionResponse final : public Response {
public:
    FunctionResponse(std::function<Eigen::VectorXd(double)> mean,
                     std::function<Eigen::VectorXd(double)> variance)
        : mean_(std::move(mean)), variance_(std::move(variance)) {}
    Eigen::VectorXd mean(double s) const override { return mean_(s); }
    Eigen::VectorXd variance(double s) const override { return variance_(s); }

private:
    std::function<Eigen::VectorXd(double)> mean_, variance_;
};

/// chi^2 of `mean` against `measured` over `use`, with variance `u2_fixed + variance`,
/// correlated within experiments as `correlation` says.
double chiSquare(const Eigen::VectorXd &measured, const Eigen::VectorXd &mean,
                 const Eigen::VectorXd &variance, const Eigen::VectorXd &u2_fixed,
                 const FeatureSet &use, const BlockCorrelation &correlation = {});

/// The strength that minimises chi^2 over `use`, a feature the response lacks at some strength
/// of its prior taken at the base ("off") at all of them (a grid over the prior, then golden
/// section),
/// with a 95 % interval from the chi^2 profile (delta chi^2 = 3.84, widened by the Birge ratio
/// chi^2 / dof when the best fit is poor).
struct StrengthFit {
    double strength = 0.0, lo = 0.0, hi = 0.0;
    double chi2 = 0.0, chi2_off = 0.0; ///< at the best strength and with the effect off
    int features = 0;
    double birge = 1.0;
    bool at_bound = false; ///< the best strength is an end of the prior range
    /// At an end of the prior, chi^2 still falls by more than 3.84 and a tenth of itself a
    /// fifth of the prior's span beyond it (the response extrapolated): the data ask for more
    /// of the effect than its prior allows, so it stands in for something else and is never
    /// claimed (docs/gap.md, step 7).
    bool beyond_prior = false;
    /// The best strength is an end of the prior that is not "off": the prior cuts its interval,
    /// so the data may want more of the effect than is plausible, and it is never claimed.
    bool at_prior_edge = false;
    /// The beds' luck in the interval: the strength's standard deviation on the prior's scale
    /// from the measured and the simulated beds' luck (`bedLuckSd`), added to the profile's
    /// half-widths in quadrature (`widenInterval`); 0 where it was not estimated.
    double luck_sd = 0.0;
    /// What a prediction at the fitted strength spreads over: the interval with the luck at
    /// the normal quantile, not Student's (a plug-in spread; the t quantile says how little
    /// a few beds tell of it, not how far the strength is off). The interval where unwidened.
    double spread_lo = 0.0, spread_hi = 0.0;
};
StrengthFit fitStrength(const Response &response, const Prior &prior,
                        const Eigen::VectorXd &measured, const Eigen::VectorXd &u2_fixed,
                        const FeatureSet &use, const BlockCorrelation &correlation = {});

/// How far one bed's luck moves fitted strengths: their standard deviations on the prior's
/// scale. The strengths are refitted (`refit`, returning them on the prior's scale) to the
/// fitted model's mean `at_fit` plus each seed's departure from the seeds' mean in `rows` (a
/// real bed's luck, with its shape and its reach over every experiment that bed serves, which
/// a chi^2 of independent or within-experiment errors does not see: a sinkage zero that a
/// bed's surface moves for every plate pressed into it), summed in squares over S - 1 seeds.
/// Zeros with fewer than two seeds.
Eigen::VectorXd bedLuckSd(const std::function<Eigen::VectorXd(const Eigen::VectorXd &)> &refit,
                          const Eigen::VectorXd &t_fit, const Eigen::VectorXd &at_fit,
                          const Eigen::MatrixXd &rows);

/// Widens a fit's 95 % interval by a standard deviation `sd` on the prior's scale, estimated
/// with `dof` degrees of freedom (its half-width Student's t quantile times sd, added to each
/// half-width in quadrature), within the prior; records it in `luck_sd`.
void widenInterval(StrengthFit &fit, const Prior &prior, double sd, double dof);

/// Whether the strengths that parts of the data ask for alone (one kind of observable each:
/// the plates' pressure, the shear box's stress, the heap's angle) agree, as one cause's
/// would: chi^2 of their spread about their precision-weighted mean on the prior's scale, each
/// with the standard deviation its 95 % interval gives on the side facing that mean
/// (half-width / 1.96), against chi^2 of (informative parts - 1) degrees of freedom. A part
/// whose interval spans nine tenths of the prior or more tells nothing and is left out. An
/// effect fitted at a strength no single part asks for absorbs a difference of model form, as
/// a tuned parameter does, instead of explaining it (docs/gap.md, step 7).
struct StrengthAgreement {
    double chi2 = 0.0;
    int dof = 0;          ///< informative parts - 1; 0: nothing to compare
    double p_value = 1.0; ///< 1 when dof is 0
    double mean = 0.0;    ///< the weighted mean strength (NaN when no part is informative)
};
StrengthAgreement strengthAgreement(const std::vector<StrengthFit> &parts, const Prior &prior);

/// Two effects' joint response: the features' mean and variance at each pair of strengths.
class PairModel {
public:
    virtual ~PairModel() = default;
    virtual Eigen::VectorXd mean(double sa, double sb) const = 0;
    virtual Eigen::VectorXd variance(double sa, double sb) const = 0;
};

/// Two effects together, their changes added to the base (the confirming simulation runs them
/// together for real).
class PairResponse final : public PairModel {
public:
    PairResponse(const Response &a, const Response &b, Eigen::VectorXd base_mean,
                 Eigen::VectorXd base_variance)
        : a_(a), b_(b), base_mean_(std::move(base_mean)), base_var_(std::move(base_variance)) {}
    Eigen::VectorXd mean(double sa, double sb) const override;
    Eigen::VectorXd variance(double sa, double sb) const override;

private:
    const Response &a_, &b_;
    Eigen::VectorXd base_mean_, base_var_;
};

/// An effect of the measuring chain with any other, the chain read on its partner's own runs:
/// at each strength the partner was simulated at, the chain's response over its grid
/// (`rows[i]` at `strengths[i]`, the off value among them), and between those strengths
/// interpolated as a table is. A chain's change is no sum with another effect's: a zero offset
/// shifts whatever curve the soil (or a compliant rig) gives, and added to a cohesion's change
/// it fitted a hidden cohesion 4e4 J/m^3 with a 1 mm offset as 3.2e4 with 0.75 mm.
class ChainOnEffectResponse final : public PairModel {
public:
    /// `under`: the partner's prior; `under_is_a`: the partner is the pair's first (strength
    /// `sa`).
    ChainOnEffectResponse(const Prior &under, std::vector<double> strengths,
                          std::vector<TabulatedResponse> rows, bool under_is_a);
    Eigen::VectorXd mean(double sa, double sb) const override;
    Eigen::VectorXd variance(double sa, double sb) const override;

private:
    /// The partner's table with the chain at `s_chain`.
    TabulatedResponse underTable(double s_chain) const;
    Prior under_;
    std::vector<double> strengths_;
    std::vector<TabulatedResponse> rows_;
    bool under_is_a_;
};

/// One strength of a pair with the other held: a response of one effect (the kinds' agreement
/// asks each strength of a pair what it asks of a single's).
class PairSlice final : public Response {
public:
    /// `along_a`: the pair's first strength varies, the second is held at `held`.
    PairSlice(const PairModel &pair, bool along_a, double held)
        : pair_(pair), along_a_(along_a), held_(held) {}
    Eigen::VectorXd mean(double s) const override {
        return along_a_ ? pair_.mean(s, held_) : pair_.mean(held_, s);
    }
    Eigen::VectorXd variance(double s) const override {
        return along_a_ ? pair_.variance(s, held_) : pair_.variance(held_, s);
    }

private:
    const PairModel &pair_;
    bool along_a_;
    double held_;
};

struct PairFit {
    StrengthFit a, b; ///< each strength with its interval at the other's best value
    double chi2 = 0.0;
};
/// Both strengths fitted on `use`; a feature the pair lacks somewhere along either strength
/// (the other off) is taken at the base, as for one effect.
PairFit fitPair(const PairModel &pair, const Prior &pa, const Prior &pb,
                const Eigen::VectorXd &base_mean, const Eigen::VectorXd &base_variance,
                const Eigen::VectorXd &measured, const Eigen::VectorXd &u2_fixed,
                const FeatureSet &use, const BlockCorrelation &correlation = {});

/// How much of effect i's signature (its change from the base at strength s_i, weighted by
/// 1/u^2) effect j can reproduce at its best strength: 1 = indistinguishable on this design,
/// 0 = nothing in common. Also the weighted distance left, in chi^2 units.
struct Overlap {
    double fraction = 0.0;
    double distance_chi2 = 0.0;
    double strength_j = 0.0;
};
Overlap signatureOverlap(const Response &i, double s_i, const Response &j, const Prior &pj,
                         const Eigen::VectorXd &base_mean, const Eigen::VectorXd &u2,
                         const FeatureSet &use, const BlockCorrelation &correlation = {});

/// log density of r under a predictive variance v of `dof` degrees of freedom (normal when
/// infinite), and its derivative in r.
double logPredictiveDensity(double r, double v, double dof);
double logPredictiveSlope(double r, double v, double dof);

/// How well predictions match held-out features. `smse`: mean squared error standardised by
/// the prediction's own variance; `relative_rmse`: root mean square of (measured - predicted)
/// / measured; `gap`: that relative error in excess of the validation uncertainty `u2_val`
/// (the same for every model compared), sqrt(max(0, mean((r^2 - u_val^2) / (y^2 + u_val^2)))):
/// 0 when the model is as good as the data can tell; a feature measured near zero counts
/// relative to its uncertainty, not to its value.
struct HeldOutScore {
    double smse = 0.0, relative_rmse = 0.0, gap = 0.0, log_density = 0.0;
    int features = 0;
};
HeldOutScore scoreHeldOut(const Eigen::VectorXd &measured, const Eigen::VectorXd &predicted,
                          const Eigen::VectorXd &variance, const Eigen::VectorXd &u2_val,
                          const FeatureSet &use, const EstimatedVariance &estimated = {});

/// What the held-out experiments of one group of beds share beyond their own scatter, for
/// `compareDensities`: the model's and the null's predictions with one simulated bed left out
/// in turn (seed j of both: common random numbers), and each measured mean's bed-to-bed
/// scatter (`measured_sd`: its repeats' on rebuilt beds, else one simulated bed's), whose luck
/// is taken to move every experiment of its group at once (as the beds of a twin do), with the
/// degrees of freedom of that scatter.
struct SharedLuck {
    std::vector<Eigen::VectorXd> model_mean, null_mean;
    Eigen::VectorXd measured_sd; ///< empty: the measured values share nothing
    double measured_dof = 0.0;   ///< 0: the scatter is exact
};

/// Sample-split test that a model predicts held-out features better than the null, by the log
/// predictive density (a proper score: a model gains nothing by widening its spread, nor by
/// a confident miss): the per-feature differences of log density, their mean, and the
/// one-sided p of a t test that it is > 0.
/// Where the model was simulated on two or more beds (`shared.model_mean`), the held-out
/// experiments (`experiment_keys`) are counted one by one and what each group of beds
/// (`bed_keys`) shares is measured instead of counted: the variance is the clustered one over
/// experiments, plus the seed jackknife of the mean gain, plus the measured beds' luck carried
/// through the gain (d gain / d y times `measured_sd`, summed over a group), with
/// Welch-Satterthwaite degrees of freedom. Without a jackknife the variance is that over
/// groups of beds whose gains may move together (`clusteredMean`); two groups give a t of one
/// degree of freedom, under which no gain could be claimed at the levels used. p = 1 with one
/// held-out experiment, one group and no jackknife, or gains without spread.
struct DensityComparison {
    /// mean log-density gain per feature (model - null), each experiment weighted equally
    double mean_gain = 0.0;
    double p_value = 1.0;
    int features = 0;
    int experiments = 0; ///< held-out experiments (or groups of beds, without a jackknife)
    double gain_correlation = 0.0; ///< the share of the gains' variance between them
    double seed_variance = 0.0;    ///< the jackknife variance of the mean gain
    double measured_variance = 0.0; ///< the measured beds' shared luck in the mean gain
    bool per_experiment = false;    ///< counted per experiment, the shared luck measured
};
/// Whether held-out features can be evidence for a claim at all (`compareDensities` gives
/// p < 1 only then): two or more groups of beds, or one group of two or more experiments
/// whose models were simulated on two or more beds (the seed jackknife measures the luck
/// they share).
bool canCarryClaim(const FeatureSet &use, const std::vector<FeatureKey> &bed_keys,
                   const std::vector<FeatureKey> &experiment_keys, std::size_t seeds);

DensityComparison
compareDensities(const Eigen::VectorXd &measured, const Eigen::VectorXd &model_mean,
                 const Eigen::VectorXd &model_variance, const Eigen::VectorXd &null_mean,
                 const Eigen::VectorXd &null_variance, const FeatureSet &use,
                 const std::vector<FeatureKey> &bed_keys,
                 const std::vector<FeatureKey> &experiment_keys = {}, const SharedLuck &shared = {},
                 const EstimatedVariance &estimated = {});

} // namespace grainlink::gap
