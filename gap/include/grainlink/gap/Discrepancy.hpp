#pragma once
// The null model's generic discrepancy (Kennedy & O'Hagan 2001): what the base model misses,
// fitted on the calibration experiments without naming a cause. The relative residual
// (measured - simulated) / simulated of every feature is a Gaussian process over the regime
// coordinates of its kind (sinkage, plate size, box, ...), with a constant part (a bias that
// carries over to every experiment of the kind) and a squared-exponential part (a bias that
// varies smoothly with the regime); the measured-and-simulated uncertainty is the noise. An
// effect is claimed only where it predicts held-out experiments better than this
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
        double constant_sd = 0.0; ///< sd of the constant (bias) part, relative
        double smooth_sd = 0.0;   ///< sd of the smooth part, relative
        double length = 1.0;      ///< length scale of the smooth part, in scaled coordinates
        double log_marginal = 0.0;
    };

    /// Fits one process per kind to the relative residuals `rho` with noise sd `noise_sd`.
    static Discrepancy fit(const std::vector<RegimePoint> &points, const Eigen::VectorXd &rho,
                           const Eigen::VectorXd &noise_sd);

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
/// features of the same kind (a coordinate constant within a kind is dropped).
std::vector<RegimePoint>
regimeCoordinates(const std::vector<std::string> &kinds,
                  const std::vector<std::map<std::string, double>> &coordinates);

} // namespace grainlink::gap
