#pragma once
// The features of one experiment share its bed realisation, in the simulation and in every
// measured trial, so their residuals are correlated (docs/gap.md, "Correlated features").
#include "grainlink/gap/Features.hpp"

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace grainlink::gap {

/// The features a comparison uses (e.g. the calibration experiments').
using FeatureSet = std::vector<Eigen::Index>;

/// Modelled as one correlation coefficient rho
/// per experiment between any two of its features (compound symmetry), estimated from the
/// base model's seeds; experiments are independent of each other.
class BlockCorrelation {
public:
    BlockCorrelation() = default; ///< every feature independent
    /// rho of each experiment: the mean correlation of its features over the seeds `rows`
    /// (clipped to [0, 0.8]; 0.5 where fewer than three seeds tell).
    BlockCorrelation(const std::vector<FeatureKey> &keys, const Eigen::MatrixXd &rows);
    /// e^T R^-1 e of standardised residuals e over `use` (generalised least squares).
    double chiSquare(const Eigen::VectorXd &e, const FeatureSet &use) const;
    double rho(const std::string &experiment) const;

private:
    std::map<std::string, std::vector<Eigen::Index>> groups(const FeatureSet &use) const;
    std::vector<std::string> experiment_of_;
    std::map<std::string, double> rho_;
};

/// The mean of `values` over `use` when each experiment's values may share an error (a model's
/// gain over another moves with the experiment's systematic error, which the beds' correlation
/// does not see): the experiments are the units, each weighted equally whatever its number of
/// values, and Var(mean) = s_means^2 / m with m - 1 degrees of freedom (the t test of the
/// experiments' means). One experiment gives no between-experiment scatter: its variance is
/// unknown (infinite). `icc` is the one-way ANOVA's share of the values' variance between
/// experiments, for the report.
struct ClusteredMean {
    double mean = 0.0, variance = 0.0, dof = 0.0;
    double icc = 0.0; ///< s_b^2 / (s_b^2 + s_w^2)
    int values = 0, experiments = 0;
};
ClusteredMean clusteredMean(const Eigen::VectorXd &values, const FeatureSet &use,
                            const std::vector<FeatureKey> &keys);

} // namespace grainlink::gap
