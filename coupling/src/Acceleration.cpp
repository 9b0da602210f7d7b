#include "grainlink/coupling/Acceleration.hpp"

#include "grainlink/coupling/Types.hpp"

#include <Eigen/QR>

#include <cmath>
#include <limits>
#include <vector>

namespace grainlink::coupling {

namespace {

/// x_{k+1} = x_k + ω r_k with a fixed ω.
class ConstantRelaxation final : public Acceleration {
public:
    explicit ConstantRelaxation(double omega) : omega_(omega) {}
    void beginWindow() override {}
    Eigen::VectorXd next(const Eigen::VectorXd &x, const Eigen::VectorXd &h) override {
        return x + omega_ * (h - x);
    }
    double lastRelaxation() const override { return omega_; }

private:
    double omega_;
};

/// Aitken's dynamic relaxation: ω_k = -ω_{k-1} r_{k-1}·(r_k - r_{k-1}) / |r_k - r_{k-1}|².
class AitkenRelaxation final : public Acceleration {
public:
    explicit AitkenRelaxation(double omega0) : omega0_(omega0), omega_(omega0) {}
    void beginWindow() override {
        previous_residual_.resize(0);
        omega_ = omega0_;
    }
    Eigen::VectorXd next(const Eigen::VectorXd &x, const Eigen::VectorXd &h) override {
        const Eigen::VectorXd r = h - x;
        if (previous_residual_.size() == r.size()) {
            const Eigen::VectorXd dr = r - previous_residual_;
            const double denominator = dr.squaredNorm();
            if (denominator > 0.0)
                omega_ = -omega_ * previous_residual_.dot(dr) / denominator;
        } else {
            omega_ = omega0_;
        }
        previous_residual_ = r;
        return x + omega_ * r;
    }
    double lastRelaxation() const override { return omega_; }

private:
    double omega0_;
    double omega_;
    Eigen::VectorXd previous_residual_;
};

/// Interface quasi-Newton with an inverse Jacobian from least squares (Degroote et al. 2009):
/// V = [Δr], W = [Δh]; solve min |V α + r_k|, then x_{k+1} = h_k + W α.
class IqnIls final : public Acceleration {
public:
    explicit IqnIls(const AccelerationSettings &settings) : settings_(settings) {}

    void beginWindow() override {
        if (!current_.dr.empty())
            past_.push_front(std::move(current_));
        current_ = Pairs{};
        while (past_.size() > settings_.reuse_windows)
            past_.pop_back();
        previous_r_.resize(0);
        previous_h_.resize(0);
    }

    Eigen::VectorXd next(const Eigen::VectorXd &x, const Eigen::VectorXd &h) override {
        const Eigen::VectorXd r = h - x;
        if (previous_r_.size() == r.size()) {
            current_.dr.push_back(r - previous_r_);
            current_.dh.push_back(h - previous_h_);
        }
        previous_r_ = r;
        previous_h_ = h;

        // Newest columns first; past windows' columns after this window's.
        std::vector<const Eigen::VectorXd *> v, w;
        for (std::size_t i = current_.dr.size(); i-- > 0;) {
            v.push_back(&current_.dr[i]);
            w.push_back(&current_.dh[i]);
        }
        for (const auto &window : past_)
            for (std::size_t i = window.dr.size(); i-- > 0;)
                if (window.dr[i].size() == r.size()) {
                    v.push_back(&window.dr[i]);
                    w.push_back(&window.dh[i]);
                }
        if (v.empty()) {
            last_omega_ = settings_.initial_relaxation;
            return x + settings_.initial_relaxation * r;
        }
        last_omega_ = std::numeric_limits<double>::quiet_NaN();

        // Filter: keep a column only if it adds to the span (QR diagonal test), newest first.
        std::vector<int> kept;
        Eigen::MatrixXd q(r.size(), 0);
        const double scale = v.front()->norm();
        for (std::size_t c = 0; c < v.size(); ++c) {
            Eigen::VectorXd column = *v[c];
            for (int k = 0; k < q.cols(); ++k)
                column -= q.col(k).dot(column) * q.col(k);
            const double norm = column.norm();
            if (norm <= settings_.filter_epsilon * std::max(scale, v[c]->norm()) || norm == 0.0)
                continue;
            if (q.cols() >= r.size())
                break;
            q.conservativeResize(Eigen::NoChange, q.cols() + 1);
            q.col(q.cols() - 1) = column / norm;
            kept.push_back(static_cast<int>(c));
        }
        Eigen::MatrixXd vm(r.size(), kept.size()), wm(r.size(), kept.size());
        for (std::size_t k = 0; k < kept.size(); ++k) {
            vm.col(k) = *v[kept[k]];
            wm.col(k) = *w[kept[k]];
        }
        const Eigen::VectorXd alpha = vm.colPivHouseholderQr().solve(-r);
        return h + wm * alpha;
    }

    double lastRelaxation() const override { return last_omega_; }

private:
    struct Pairs {
        std::vector<Eigen::VectorXd> dr, dh;
    };
    AccelerationSettings settings_;
    Pairs current_;
    std::deque<Pairs> past_;
    Eigen::VectorXd previous_r_, previous_h_;
    double last_omega_ = 0.0;
};

} // namespace

std::unique_ptr<Acceleration> makeAcceleration(const AccelerationSettings &settings) {
    switch (settings.kind) {
    case AccelerationKind::Constant:
        return std::make_unique<ConstantRelaxation>(settings.initial_relaxation);
    case AccelerationKind::Aitken:
        return std::make_unique<AitkenRelaxation>(settings.initial_relaxation);
    case AccelerationKind::IqnIls:
        return std::make_unique<IqnIls>(settings);
    }
    return nullptr;
}

AccelerationKind accelerationFromName(const std::string &name) {
    if (name == "constant")
        return AccelerationKind::Constant;
    if (name == "aitken")
        return AccelerationKind::Aitken;
    if (name == "iqn-ils")
        return AccelerationKind::IqnIls;
    throw CouplingError("unknown acceleration '" + name + "' (constant, aitken or iqn-ils)");
}

const char *accelerationName(AccelerationKind kind) {
    switch (kind) {
    case AccelerationKind::Constant:
        return "constant";
    case AccelerationKind::Aitken:
        return "aitken";
    case AccelerationKind::IqnIls:
        return "iqn-ils";
    }
    return "?";
}

} // namespace grainlink::coupling
