#pragma once
// The null model's generic discrepancy (Kennedy & O'Hagan 2001): what the base model misses,
// fitted on the calibration experiments without naming a cause. The relative residual
// (measured - simulated) / simulated of every feature is a zero-mean Gaussian process over the
// regime coordinates of its kind (sinkage, plate size, box, ...), squared-exponential in
// coordinates scaled by the calibration's own range; the measured-and-simulated uncertainty is
// the noise. It knows the regimes it was fitted in: near them it carries the discrepancy over,
// far from them (beyond its length scale) it reverts to the base model with a growing spread.
// An effect is claimed only where it predicts held-out experiments better than this
// (docs/gap.md, "The null model").
#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// Where a feature sits for the discrepancy model: its kind and its regime coordinates,
/// scaled to order one (see regimeCoordinates).
struct RegimePoint {
    std::string kind;
    Eigen::VectorXd x;
};

struct DiscrepancyPrediction {
    Eigen::VectorXd mean;     ///< relative discrepancy
    Eigen::VectorXd variance; ///< of that mean
};

class Discrepancy {
public:
    /// Hyperparameters per kind, chosen by the largest marginal likelihood on a grid.
    struct Hyper {
        double sd = 0.0;     ///< prior sd of the relative discrepancy
        double length = 1.0; ///< length scale, in scaled coordinates
        double log_marginal = 0.0;
    };

    /// Fits one process per kind to the relative residuals `rho` with noise sd `noise_sd`.
    /// `noise_correlation` (points x points; empty: independent) is the noise's correlation:
    /// a bed or a measuring chain that shifts a whole curve is one draw of noise for all of
    /// its features, not a discrepancy seen many times over.
    static Discrepancy fit(const std::vector<RegimePoint> &points, const Eigen::VectorXd &rho,
                           const Eigen::VectorXd &noise_sd,
                           const Eigen::MatrixXd &noise_correlation = Eigen::MatrixXd());

    /// The posterior mean and variance of the discrepancy at `points`. A kind the calibration
    /// never saw gets none (mean 0, variance 0): there the null model is the base model.
    DiscrepancyPrediction predict(const std::vector<RegimePoint> &points) const;

    const std::map<std::string, Hyper> &hyperparameters() const { return hyper_; }

private:
    struct KindFit {
        Hyper hyper;
        std::vector<Eigen::VectorXd> x;
        Eigen::VectorXd alpha;  ///< K^-1 rho
        Eigen::MatrixXd k_inv;  ///< K^-1 (small: calibration features of one kind)
    };
    std::map<std::string, KindFit> fits_;
    std::map<std::string, Hyper> hyper_;
};

/// Regime coordinates of features: each named numeric coordinate scaled by its range over the
/// `reference` features of the same kind (the calibration; where it is constant there, by its
/// range over all), a coordinate constant over all features of a kind dropped; each text label
/// (a box) a coordinate per value, so that two values lie one length unit apart.
std::vector<RegimePoint>
regimeCoordinates(const std::vector<std::string> &kinds,
                  const std::vector<std::map<std::string, double>> &coordinates,
                  const std::vector<std::map<std::string, std::string>> &labels = {},
                  const std::vector<bool> &reference = {});

} // namespace grainlink::gap
