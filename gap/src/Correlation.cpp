#include "grainlink/gap/Correlation.hpp"

#include <algorithm>
#include <cmath>

namespace grainlink::gap {

BlockCorrelation::BlockCorrelation(const std::vector<FeatureKey> &keys, const Eigen::MatrixXd &rows) {
    for (const FeatureKey &k : keys)
        experiment_of_.push_back(k.experiment);
    std::map<std::string, std::vector<Eigen::Index>> by;
    for (std::size_t i = 0; i < keys.size(); ++i)
        by[keys[i].experiment].push_back(Eigen::Index(i));
    for (const auto &[id, idx] : by) {
        double rho = 0.5; // too few seeds to tell: halfway between independent and one
        if (rows.rows() >= 3 && idx.size() >= 2) {
            double sum = 0.0;
            int pairs = 0;
            for (std::size_t a = 0; a < idx.size(); ++a)
                for (std::size_t b = a + 1; b < idx.size(); ++b) {
                    const Eigen::VectorXd x = rows.col(idx[a]), y = rows.col(idx[b]);
                    if (!x.allFinite() || !y.allFinite())
                        continue;
                    const Eigen::VectorXd dx = x.array() - x.mean(), dy = y.array() - y.mean();
                    const double den = std::sqrt(dx.squaredNorm() * dy.squaredNorm());
                    if (den <= 0.0)
                        continue;
                    sum += dx.dot(dy) / den;
                    ++pairs;
                }
            if (pairs > 0)
                rho = sum / pairs;
        }
        // Capped at 0.8: a bed moves a curve as a whole but never only so, and under
        // compound symmetry 1/(1 - rho) is how much a residual's shape outweighs its level.
        rho_[id] = std::clamp(rho, 0.0, 0.8);
    }
}

double BlockCorrelation::rho(const std::string &experiment) const {
    const auto it = rho_.find(experiment);
    return it == rho_.end() ? 0.0 : it->second;
}

std::map<std::string, std::vector<Eigen::Index>>
BlockCorrelation::groups(const FeatureSet &use) const {
    std::map<std::string, std::vector<Eigen::Index>> g;
    for (Eigen::Index k : use)
        g[experiment_of_.empty() ? std::to_string(k) : experiment_of_[std::size_t(k)]].push_back(k);
    return g;
}

double BlockCorrelation::chiSquare(const Eigen::VectorXd &e, const FeatureSet &use) const {
    double total = 0.0;
    for (const auto &[id, idx] : groups(use)) {
        const double r = experiment_of_.empty() ? 0.0 : rho(id);
        double sum = 0.0, sum2 = 0.0;
        int k = 0;
        for (Eigen::Index i : idx)
            if (std::isfinite(e[i])) {
                sum += e[i];
                sum2 += e[i] * e[i];
                ++k;
            }
        // R = (1 - r) I + r 1 1^T:  e^T R^-1 e = (sum2 - r sum^2 / (1 + (k - 1) r)) / (1 - r).
        total += (sum2 - r * sum * sum / (1.0 + (k - 1) * r)) / (1.0 - r);
    }
    return total;
}

double BlockCorrelation::effectiveCount(const FeatureSet &use) const {
    double n = 0.0;
    for (const auto &[id, idx] : groups(use)) {
        const double r = experiment_of_.empty() ? 0.0 : rho(id);
        const double k = double(idx.size());
        n += k / (1.0 + (k - 1.0) * r);
    }
    return n;
}

} // namespace grainlink::gap
