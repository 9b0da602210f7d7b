#pragma once
// Curves become features: the mean of a sampled curve over an x-range (a sinkage bin, a slip
// bin), or a scalar. Measured trials, simulated seeds and effect signatures are all compared
// feature by feature on the same bins (docs/gap.md, "Features").
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

/// A sampled curve y(x) with x increasing; a scalar observable is a curve of one point.
struct Curve {
    std::vector<double> x, y;
    bool empty() const { return y.empty(); }
    bool scalar() const { return y.size() == 1; }
};

/// Mean of the piecewise-linear interpolant of `curve` over [a, b] (the integral over the
/// range divided by its width); nullopt when the curve's samples do not cover [a, b]. A curve
/// starting within a tenth of the width past a is held at its first value back to a.
/// For a scalar curve (one point) the value itself in the point bin a = b, and nothing in a
/// bin of some width (a curve cut to one sample covers none).
std::optional<double> binMean(const Curve &curve, double a, double b);

/// Which feature: the experiment, its observable, and the x-range averaged over.
struct FeatureKey {
    std::string experiment; ///< experiment id in experiments.yaml
    std::string observable; ///< e.g. "pressure_Pa", "angle_deg"
    std::string kind;       ///< what is compared with what across experiments, e.g.
                            ///< "plate_sinkage/pressure_Pa" (the discrepancy model's unit)
    double x_lo = 0.0, x_hi = 0.0; ///< bin [x unit]; equal for a scalar
    bool scalar() const { return x_lo == x_hi; }
    double centre() const { return 0.5 * (x_lo + x_hi); }
};

/// Bin edges shared by every experiment of one observable kind: equal bins from `start` with a
/// round width (1, 2, 2.5 or 5 times a power of ten, the largest not above (end - start) /
/// count), as many as fit before `typical_end` (so at least `count`), or with `cover_end` as
/// many as reach it (a scatter of runs: the last edge at or beyond the last run).
std::vector<double> roundBinEdges(double start, double typical_end, int count,
                                  bool cover_end = false);

/// Features of a set of curves (trials or seeds) on `edges`: one row per curve, one column
/// per bin; NaN where a curve does not cover the bin. A scalar curve gives one column.
Eigen::MatrixXd featureRows(const std::vector<Curve> &curves, const std::vector<double> &edges);

/// Column statistics of `rows` ignoring NaN: mean, sample standard deviation (NaN below two
/// values) and the count of values.
struct ColumnStats {
    Eigen::VectorXd mean, sd;
    Eigen::VectorXi count;
};
ColumnStats columnStats(const Eigen::MatrixXd &rows);

/// The scatter of one simulated bed, per column, pooled over groups of rows that each share one
/// model (the base's seeds, each variant's seeds): sqrt(sum of squared deviations from each
/// group's own mean / sum of (n_g - 1)). Two or three seeds give a sample sd that swings by
/// factors of ten; pooled over many variants it is a steady estimate (docs/gap.md, step 6).
class PooledScatter {
public:
    explicit PooledScatter(Eigen::Index columns)
        : squares_(Eigen::VectorXd::Zero(columns)), dof_(Eigen::VectorXi::Zero(columns)) {}
    void add(const Eigen::MatrixXd &group);
    /// The pooled sd; `fallback` where no group had two values.
    Eigen::VectorXd sd(const Eigen::VectorXd &fallback) const;
    /// The same where `min_dof` or more degrees of freedom pooled; elsewhere the median relative
    /// scatter (sd / |reference|) of the features of its group (`groups[k]`, e.g. its
    /// experiment) that have any, times |reference_k|: a bed moves a curve by a roughly fixed
    /// share, and one or two seeds per feature give a sample sd that swings by factors of ten.
    /// `fallback` where the group has none.
    Eigen::VectorXd sd(const Eigen::VectorXd &fallback, const Eigen::VectorXd &reference,
                       const std::vector<std::string> &groups, int min_dof) const;
    /// Degrees of freedom of each column's estimate.
    const Eigen::VectorXi &dof() const { return dof_; }

private:
    Eigen::VectorXd squares_;
    Eigen::VectorXi dof_;
};

} // namespace grainlink::gap
