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
    /// How many independent features `use` is worth (Kish: k / (1 + (k - 1) rho) each).
    double effectiveCount(const FeatureSet &use) const;
    double rho(const std::string &experiment) const;

private:
    std::map<std::string, std::vector<Eigen::Index>> groups(const FeatureSet &use) const;
    std::vector<std::string> experiment_of_;
    std::map<std::string, double> rho_;
};

} // namespace grainlink::gap
