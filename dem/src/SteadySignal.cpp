#include "grainlink/dem/SteadySignal.hpp"

#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace grainlink::dem {

namespace {

/// The means of `batches` consecutive, nearly equal batches of `values` (at most one per value).
std::vector<double> batchMeans(const std::vector<double> &values, std::size_t batches) {
    const std::size_t n = values.size();
    const std::size_t b = std::min(batches, n);
    std::vector<double> means;
    for (std::size_t k = 0; k < b; ++k) {
        const std::size_t first = k * n / b, end = (k + 1) * n / b;
        double sum = 0.0;
        for (std::size_t i = first; i < end; ++i)
            sum += values[i];
        means.push_back(sum / double(end - first));
    }
    return means;
}

} // namespace

double studentT95(std::size_t dof) {
    if (dof == 0)
        throw std::invalid_argument("Student t quantile: zero degrees of freedom");
    return boost::math::quantile(boost::math::students_t(double(dof)), 0.975);
}

LineFit fitLine(const std::vector<double> &x, const std::vector<double> &y) {
    if (x.size() != y.size())
        throw std::invalid_argument("line fit: " + std::to_string(x.size()) + " x values for " +
                                    std::to_string(y.size()) + " y values");
    LineFit fit;
    const double n = double(x.size());
    if (x.size() < 3)
        return fit;
    for (std::size_t k = 0; k < x.size(); ++k) {
        fit.x_mean += x[k] / n;
        fit.intercept += y[k] / n;
    }
    double sxx = 0.0, sxy = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        sxx += (x[k] - fit.x_mean) * (x[k] - fit.x_mean);
        sxy += (x[k] - fit.x_mean) * (y[k] - fit.intercept);
    }
    if (sxx <= 0.0)
        return fit;
    fit.slope = sxy / sxx;
    double residuals = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        const double r = y[k] - fit.intercept - fit.slope * (x[k] - fit.x_mean);
        residuals += r * r;
    }
    fit.dof = x.size() - 2;
    fit.slope_se = std::sqrt(residuals / double(fit.dof) / sxx);
    return fit;
}

bool SignalTrend::consistentWithZero() const {
    if (dof == 0)
        return true;
    return std::abs(slope_per_s) <= studentT95(dof) * slope_se_per_s;
}

SignalSummary summarizeSignal(const std::vector<double> &values, std::size_t batches) {
    SignalSummary s;
    s.samples = values.size();
    if (values.empty())
        return s;
    for (double v : values)
        s.mean += v / double(values.size());
    for (double v : values)
        s.sd += (v - s.mean) * (v - s.mean);
    s.sd = values.size() > 1 ? std::sqrt(s.sd / double(values.size() - 1)) : 0.0;
    const auto means = batchMeans(values, batches);
    s.batches = means.size();
    if (means.size() > 1) {
        double spread = 0.0;
        for (double m : means)
            spread += (m - s.mean) * (m - s.mean);
        s.standard_error = std::sqrt(spread / double(means.size() - 1) / double(means.size()));
    }
    return s;
}

SignalTrend signalTrend(const std::vector<double> &times, const std::vector<double> &values,
                        std::size_t batches) {
    if (times.size() != values.size())
        throw std::invalid_argument("signal trend: " + std::to_string(times.size()) +
                                    " times for " + std::to_string(values.size()) + " values");
    const LineFit line = fitLine(batchMeans(times, batches), batchMeans(values, batches));
    return {line.slope, line.slope_se, line.dof};
}

} // namespace grainlink::dem
