#pragma once
// Statistics of a signal that ought to be steady — a driven wheel's slip, torque or height over
// the last span of windows: its mean with a standard error, and its linear trend with the
// trend's uncertainty. Both work on batch means (Law & Kelton, Simulation Modeling and Analysis,
// §9.5.3): a coupled run's consecutive samples are strongly correlated (one grouser passes in
// hundreds of windows), so sd/√n understates the uncertainty many times over, while the means of
// a few long batches are close to independent. Here in dem because both the rig's procedure
// (mbs) and the lab link it; the lab's repose test fits its heap's flank with fitLine too.
#include <cstddef>
#include <vector>

namespace grainlink::dem {

/// A least-squares line y = intercept + slope (x - x_mean) with its slope's standard error.
struct LineFit {
    double x_mean = 0.0, intercept = 0.0; ///< the line's value at x_mean
    double slope = 0.0, slope_se = 0.0;
    std::size_t dof = 0; ///< points - 2; 0 with fewer than 3 points or no spread in x
};

/// The least-squares line through (x_k, y_k); with fewer than 3 points or all x equal, a zero
/// slope with zero dof.
LineFit fitLine(const std::vector<double> &x, const std::vector<double> &y);

struct SignalSummary {
    double mean = 0.0;
    double sd = 0.0;             ///< the samples' standard deviation (the fluctuation)
    double standard_error = 0.0; ///< of the mean, from the batch means
    std::size_t samples = 0, batches = 0;
};

struct SignalTrend {
    double slope_per_s = 0.0; ///< least-squares slope of the batch means against time
    double slope_se_per_s = 0.0;
    std::size_t dof = 0; ///< batches - 2
    /// True when the slope's two-sided 95 % interval (Student t with dof) contains zero.
    bool consistentWithZero() const;
};

/// The mean, fluctuation and standard error of `values` cut into `batches` consecutive batches
/// (fewer when there are fewer samples). Empty input gives zeros.
SignalSummary summarizeSignal(const std::vector<double> &values, std::size_t batches = 10);

/// The linear trend of `values` sampled at `times`, fitted to the means of `batches`
/// consecutive batches; fewer than 3 batches give a zero slope with zero dof.
SignalTrend signalTrend(const std::vector<double> &times, const std::vector<double> &values,
                        std::size_t batches = 20);

/// The two-sided 95 % quantile of Student's t with `dof` degrees of freedom (Boost.Math).
double studentT95(std::size_t dof);

} // namespace grainlink::dem
