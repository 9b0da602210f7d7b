#include "grainlink/dem/SteadySignal.hpp"

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
    static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                   2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                   2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                   2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
    if (dof == 0)
        throw std::invalid_argument("Student t quantile: zero degrees of freedom");
    return dof <= 30 ? table[dof - 1] : 1.96;
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
    SignalTrend trend;
    const auto t = batchMeans(times, batches), y = batchMeans(values, batches);
    if (t.size() < 3)
        return trend;
    const double n = double(t.size());
    double t_mean = 0.0, y_mean = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        t_mean += t[k] / n;
        y_mean += y[k] / n;
    }
    double stt = 0.0, sty = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        stt += (t[k] - t_mean) * (t[k] - t_mean);
        sty += (t[k] - t_mean) * (y[k] - y_mean);
    }
    if (stt <= 0.0)
        return trend;
    trend.slope_per_s = sty / stt;
    double residuals = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        const double r = y[k] - y_mean - trend.slope_per_s * (t[k] - t_mean);
        residuals += r * r;
    }
    trend.dof = t.size() - 2;
    trend.slope_se_per_s = std::sqrt(residuals / double(trend.dof) / stt);
    return trend;
}

} // namespace grainlink::dem
