#include "grainlink/gap/Discrepancy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

namespace grainlink::gap {

namespace {

double kernel(const Discrepancy::Hyper &h, const Eigen::VectorXd &a, const Eigen::VectorXd &b) {
    const double d2 = (a - b).squaredNorm();
    return h.sd * h.sd * std::exp(-0.5 * d2 / (h.length * h.length));
}

} // namespace

Discrepancy Discrepancy::fit(const std::vector<RegimePoint> &points, const Eigen::VectorXd &rho,
                             const Eigen::VectorXd &noise_sd,
                             const Eigen::MatrixXd &noise_correlation) {
    const bool correlated = noise_correlation.size() > 0;
    if (Eigen::Index(points.size()) != rho.size() || rho.size() != noise_sd.size() ||
        (correlated &&
         (noise_correlation.rows() != rho.size() || noise_correlation.cols() != rho.size())))
        throw std::invalid_argument("Discrepancy::fit: points, residuals and noise differ in size");
    std::map<std::string, std::vector<Eigen::Index>> by_kind;
    for (std::size_t i = 0; i < points.size(); ++i)
        if (std::isfinite(rho[Eigen::Index(i)]) && noise_sd[Eigen::Index(i)] > 0.0)
            by_kind[points[i].kind].push_back(Eigen::Index(i));

    // Grid of hyperparameters: relative discrepancies from none to 160 %, length scales from a
    // quarter of the calibration's range to all of it.
    const double sds[] = {0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 0.8, 1.6};
    const double lengths[] = {0.25, 0.5, 1.0};
    Discrepancy d;
    for (const auto &[kind, idx] : by_kind) {
        const Eigen::Index n = Eigen::Index(idx.size());
        Eigen::VectorXd y(n);
        Eigen::MatrixXd noise(n, n); // the noise's covariance
        std::vector<Eigen::VectorXd> x;
        for (Eigen::Index i = 0; i < n; ++i) {
            const Eigen::Index a = idx[std::size_t(i)];
            y[i] = rho[a];
            x.push_back(points[std::size_t(a)].x);
            for (Eigen::Index j = 0; j < n; ++j) {
                const Eigen::Index b = idx[std::size_t(j)];
                const double c = i == j ? 1.0 : correlated ? noise_correlation(a, b) : 0.0;
                noise(i, j) = c * noise_sd[a] * noise_sd[b];
            }
        }
        KindFit best;
        best.hyper.log_marginal = -std::numeric_limits<double>::infinity();
        for (double s : sds)
            for (double l : lengths) {
                    if (s == 0.0 && l != lengths[0])
                        continue; // the length scale is irrelevant without a discrepancy
                    Hyper h{s, l, 0.0};
                    Eigen::MatrixXd K(n, n);
                    for (Eigen::Index i = 0; i < n; ++i)
                        for (Eigen::Index j = 0; j < n; ++j)
                            K(i, j) = kernel(h, x[std::size_t(i)], x[std::size_t(j)]) + noise(i, j);
                    Eigen::LLT<Eigen::MatrixXd> llt(K);
                    if (llt.info() != Eigen::Success)
                        continue;
                    const Eigen::VectorXd alpha = llt.solve(y);
                    const double logdet =
                        2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
                    h.log_marginal = -0.5 * y.dot(alpha) - 0.5 * logdet -
                                     0.5 * double(n) * std::log(2.0 * M_PI);
                    if (h.log_marginal > best.hyper.log_marginal) {
                        best.hyper = h;
                        best.alpha = alpha;
                        best.k_inv = llt.solve(Eigen::MatrixXd::Identity(n, n));
                        best.x = x;
                    }
            }
        if (!std::isfinite(best.hyper.log_marginal))
            continue;
        d.hyper_[kind] = best.hyper;
        d.fits_[kind] = std::move(best);
    }
    return d;
}

DiscrepancyPrediction Discrepancy::predict(const std::vector<RegimePoint> &points) const {
    DiscrepancyPrediction p;
    const Eigen::Index n = Eigen::Index(points.size());
    p.mean = Eigen::VectorXd::Zero(n);
    p.variance = Eigen::VectorXd::Zero(n);
    for (Eigen::Index i = 0; i < n; ++i) {
        const auto it = fits_.find(points[std::size_t(i)].kind);
        if (it == fits_.end())
            continue;
        const KindFit &f = it->second;
        Eigen::VectorXd k(Eigen::Index(f.x.size()));
        for (std::size_t j = 0; j < f.x.size(); ++j)
            k[Eigen::Index(j)] = kernel(f.hyper, points[std::size_t(i)].x, f.x[j]);
        const double prior = kernel(f.hyper, points[std::size_t(i)].x, points[std::size_t(i)].x);
        p.mean[i] = k.dot(f.alpha);
        p.variance[i] = std::max(0.0, prior - k.dot(f.k_inv * k));
    }
    return p;
}

std::vector<RegimePoint>
regimeCoordinates(const std::vector<std::string> &kinds,
                  const std::vector<std::map<std::string, double>> &coordinates,
                  const std::vector<std::map<std::string, std::string>> &labels,
                  const std::vector<bool> &reference) {
    if (kinds.size() != coordinates.size() || (!labels.empty() && labels.size() != kinds.size()) ||
        (!reference.empty() && reference.size() != kinds.size()))
        throw std::invalid_argument("regimeCoordinates: inputs differ in size");
    using Range = std::pair<double, double>;
    const auto widen = [](std::map<std::string, Range> &m, const std::string &name, double v) {
        auto [it, fresh] = m.try_emplace(name, v, v);
        it->second.first = std::min(it->second.first, v);
        it->second.second = std::max(it->second.second, v);
    };
    // Per kind: every coordinate's range over all features and over the reference ones, and
    // every label's values.
    std::map<std::string, std::map<std::string, Range>> all, ref;
    std::map<std::string, std::map<std::string, std::set<std::string>>> values;
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        for (const auto &[name, v] : coordinates[i]) {
            widen(all[kinds[i]], name, v);
            if (reference.empty() || reference[i])
                widen(ref[kinds[i]], name, v);
        }
        if (!labels.empty())
            for (const auto &[name, v] : labels[i])
                values[kinds[i]][name].insert(v);
    }
    std::vector<RegimePoint> points;
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        RegimePoint p;
        p.kind = kinds[i];
        std::vector<double> x;
        for (const auto &[name, r] : all[kinds[i]]) {
            if (!(r.second > r.first))
                continue;
            const auto rr = ref[kinds[i]].find(name);
            const bool ref_wide = rr != ref[kinds[i]].end() && rr->second.second > rr->second.first;
            const Range scale = ref_wide ? rr->second : r;
            const auto it = coordinates[i].find(name);
            const double v = it == coordinates[i].end() ? scale.first : it->second;
            x.push_back((v - scale.first) / (scale.second - scale.first));
        }
        for (const auto &[name, vals] : values[kinds[i]]) {
            if (vals.size() < 2)
                continue;
            const auto it = labels[i].find(name);
            for (const std::string &v : vals)
                x.push_back(it != labels[i].end() && it->second == v ? std::sqrt(0.5) : 0.0);
        }
        p.x = Eigen::Map<Eigen::VectorXd>(x.data(), Eigen::Index(x.size()));
        points.push_back(std::move(p));
    }
    return points;
}

} // namespace grainlink::gap
