#include "grainlink/gap/Features.hpp"

#include "NotANumber.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace grainlink::gap {

std::optional<double> binMean(const Curve &curve, double a, double b) {
    const auto &x = curve.x;
    const auto &y = curve.y;
    if (y.empty() || x.size() != y.size())
        return std::nullopt;
    if (y.size() == 1) // a scalar's one bin is the point 0; a one-sample curve covers no bin
        return b > a ? std::nullopt : std::optional<double>(y[0]);
    // A curve that starts a little into its first bin (a recording's first sample at 0.2 mm of
    // a 2.5 mm bin: every CMU plate's first bin was lost) is held at its first value back to
    // the bin's start; further in, the bin is not covered.
    // (A curve that ends on the bin's edge covers it: an edge of 6 x 0.1 lies above 0.6.)
    if (!(b > a) || x.front() > a + 0.1 * (b - a) || x.back() < b - 1e-9 * (b - a))
        return std::nullopt;
    // Trapezoid rule on the interpolant clipped to [a, b].
    const auto interpolate = [&](std::size_t i, double t) {
        const double w = (t - x[i]) / (x[i + 1] - x[i]);
        return y[i] + w * (y[i + 1] - y[i]);
    };
    double integral = x.front() > a ? y.front() * (x.front() - a) : 0.0;
    for (std::size_t i = 0; i + 1 < x.size(); ++i) {
        const double lo = std::max(a, x[i]), hi = std::min(b, x[i + 1]);
        if (hi <= lo || x[i + 1] <= x[i])
            continue;
        integral += 0.5 * (interpolate(i, lo) + interpolate(i, hi)) * (hi - lo);
    }
    return integral / (b - a);
}

std::vector<double> roundBinEdges(double start, double typical_end, int count, bool cover_end) {
    if (count < 1 || !(typical_end > start))
        throw std::invalid_argument("roundBinEdges: need count >= 1 and end > start");
    const double raw = (typical_end - start) / count;
    const double decade = std::pow(10.0, std::floor(std::log10(raw)));
    double width = decade;
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * decade <= raw * 1.0000001)
            width = m * decade;
    // As many bins of that width as fit before the end (at least `count`, since the width was
    // rounded down), or as reach past it.
    const double fit = (typical_end - start) / width;
    const int bins =
        std::max(count, int(cover_end ? std::ceil(fit - 1e-9) : std::floor(fit + 1e-9)));
    std::vector<double> edges;
    for (int k = 0; k <= bins; ++k)
        edges.push_back(start + k * width);
    return edges;
}

Eigen::MatrixXd featureRows(const std::vector<Curve> &curves, const std::vector<double> &edges) {
    const bool scalar = !curves.empty() && curves.front().scalar();
    const int bins = scalar ? 1 : int(edges.size()) - 1;
    Eigen::MatrixXd rows = Eigen::MatrixXd::Constant(Eigen::Index(curves.size()), bins, kNaN);
    for (std::size_t r = 0; r < curves.size(); ++r) {
        if (scalar) {
            rows(Eigen::Index(r), 0) = curves[r].empty() ? kNaN : curves[r].y[0];
            continue;
        }
        for (int k = 0; k < bins; ++k)
            if (const auto m = binMean(curves[r], edges[std::size_t(k)], edges[std::size_t(k) + 1]))
                rows(Eigen::Index(r), k) = *m;
    }
    return rows;
}

ColumnStats columnStats(const Eigen::MatrixXd &rows) {
    ColumnStats s;
    const Eigen::Index n = rows.cols();
    s.mean = Eigen::VectorXd::Constant(n, kNaN);
    s.sd = Eigen::VectorXd::Constant(n, kNaN);
    s.count = Eigen::VectorXi::Zero(n);
    for (Eigen::Index c = 0; c < n; ++c) {
        double sum = 0.0;
        int k = 0;
        for (Eigen::Index r = 0; r < rows.rows(); ++r)
            if (std::isfinite(rows(r, c))) {
                sum += rows(r, c);
                ++k;
            }
        s.count[c] = k;
        if (k == 0)
            continue;
        s.mean[c] = sum / k;
        if (k < 2)
            continue;
        double ss = 0.0;
        for (Eigen::Index r = 0; r < rows.rows(); ++r)
            if (std::isfinite(rows(r, c)))
                ss += (rows(r, c) - s.mean[c]) * (rows(r, c) - s.mean[c]);
        s.sd[c] = std::sqrt(ss / (k - 1));
    }
    return s;
}

void PooledScatter::add(const Eigen::MatrixXd &group) {
    const ColumnStats s = columnStats(group);
    for (Eigen::Index c = 0; c < group.cols() && c < squares_.size(); ++c)
        if (s.count[c] >= 2) {
            squares_[c] += s.sd[c] * s.sd[c] * (s.count[c] - 1);
            dof_[c] += s.count[c] - 1;
        }
}

Eigen::VectorXd PooledScatter::sd(const Eigen::VectorXd &fallback) const {
    Eigen::VectorXd out = fallback;
    for (Eigen::Index c = 0; c < squares_.size(); ++c)
        if (dof_[c] > 0)
            out[c] = std::sqrt(squares_[c] / dof_[c]);
    return out;
}

Eigen::VectorXd PooledScatter::sd(const Eigen::VectorXd &fallback, const Eigen::VectorXd &reference,
                                  const std::vector<std::string> &groups, int min_dof) const {
    Eigen::VectorXd out = sd(fallback);
    std::map<std::string, std::vector<double>> relative;
    for (Eigen::Index c = 0; c < squares_.size(); ++c)
        if (dof_[c] > 0 && std::isfinite(reference[c]) && std::abs(reference[c]) > 0.0)
            relative[groups[std::size_t(c)]].push_back(out[c] / std::abs(reference[c]));
    for (Eigen::Index c = 0; c < squares_.size(); ++c) {
        if (dof_[c] >= min_dof || !std::isfinite(reference[c]))
            continue;
        auto r = relative.find(groups[std::size_t(c)]);
        if (r == relative.end())
            continue;
        std::vector<double> &v = r->second;
        std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
        out[c] = v[v.size() / 2] * std::abs(reference[c]);
    }
    return out;
}

} // namespace grainlink::gap
