#include "grainlink/gap/Discrepancy.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace grainlink::gap;

namespace {
RegimePoint at(const std::string &kind, double x) {
    return {kind, Eigen::VectorXd::Constant(1, x)};
}
} // namespace

TEST_CASE("one calibration point: the posterior is the closed form of a one-point process",
          "[gap][discrepancy]") {
    const Eigen::VectorXd rho = Eigen::VectorXd::Constant(1, 0.3);
    const Eigen::VectorXd noise = Eigen::VectorXd::Constant(1, 0.1);
    const auto d = Discrepancy::fit({at("A", 0.0)}, rho, noise);
    const auto h = d.hyperparameters().at("A");
    // k(x, x') = s^2 exp(-(x - x')^2 / (2 l^2)); mean = k* rho / (k00 + n^2),
    // variance = k** - k*^2 / (k00 + n^2).
    const double x = 0.4;
    const double kstar = h.sd * h.sd * std::exp(-0.5 * x * x / (h.length * h.length));
    const double k00 = h.sd * h.sd;
    const auto p = d.predict({at("A", x)});
    CHECK(p.mean[0] == Approx(kstar * 0.3 / (k00 + 0.01)).margin(1e-12));
    CHECK(p.variance[0] == Approx(k00 - kstar * kstar / (k00 + 0.01)).margin(1e-12));
}

TEST_CASE("a bias seen in calibration carries over nearby and fades far from it",
          "[gap][discrepancy]") {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::vector<RegimePoint> pts;
    Eigen::VectorXd rho(20), sd = Eigen::VectorXd::Constant(20, 0.02);
    for (int i = 0; i < 20; ++i) {
        pts.push_back(at("plate", i / 19.0));
        rho[i] = -0.4 + noise(rng);
    }
    const auto d = Discrepancy::fit(pts, rho, sd);
    const auto p = d.predict({at("plate", 1.1), at("plate", 8.0), at("shear", 0.5)});
    CHECK(p.mean[0] == Approx(-0.4).margin(0.06)); // just beyond the calibration
    // Far beyond it (eight calibration widths) the null is the base model again, with the
    // discrepancy's full spread.
    CHECK(std::abs(p.mean[1]) < 0.01);
    CHECK(std::sqrt(p.variance[1]) == Approx(d.hyperparameters().at("plate").sd).epsilon(0.01));
    // A kind never calibrated gets no discrepancy: the null is the base model there.
    CHECK(p.mean[2] == 0.0);
    CHECK(p.variance[2] == 0.0);
}

TEST_CASE("no discrepancy in calibration predicts none", "[gap][discrepancy]") {
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<RegimePoint> pts;
    Eigen::VectorXd rho(30), sd = Eigen::VectorXd::Constant(30, 0.05);
    for (int i = 0; i < 30; ++i) {
        pts.push_back(at("plate", i / 29.0));
        rho[i] = noise(rng);
    }
    const auto p = Discrepancy::fit(pts, rho, sd).predict({at("plate", 0.5)});
    CHECK(std::abs(p.mean[0]) < 0.04);
}

TEST_CASE("a smooth discrepancy is interpolated between calibration regimes",
          "[gap][discrepancy]") {
    // rho(x) = 0.3 sin(2 pi x) seen at 21 points, predicted between them.
    std::vector<RegimePoint> pts;
    Eigen::VectorXd rho(21), sd = Eigen::VectorXd::Constant(21, 0.01);
    for (int i = 0; i <= 20; ++i) {
        pts.push_back(at("plate", i / 20.0));
        rho[i] = 0.3 * std::sin(2.0 * M_PI * i / 20.0);
    }
    const auto d = Discrepancy::fit(pts, rho, sd);
    const auto p = d.predict({at("plate", 0.125), at("plate", 0.625)});
    CHECK(p.mean[0] == Approx(0.3 * std::sin(2.0 * M_PI * 0.125)).margin(0.03));
    CHECK(p.mean[1] == Approx(0.3 * std::sin(2.0 * M_PI * 0.625)).margin(0.03));
}

TEST_CASE("regime coordinates are scaled by the calibration's range, labels one unit apart",
          "[gap][discrepancy]") {
    const auto pts = regimeCoordinates(
        {"a", "a", "a", "b"},
        {{{"z", 0.0}, {"d", 0.06}}, {{"z", 0.02}, {"d", 0.06}}, {{"z", 0.04}, {"d", 0.06}}, {{"z", 5.0}}},
        {{{"box", "large"}}, {{"box", "large"}}, {{"box", "small"}}, {}},
        {true, true, false, true});
    REQUIRE(pts[0].x.size() == 3); // z, and one coordinate per box; d is constant
    CHECK(pts[1].x[0] == Approx(1.0));
    CHECK(pts[2].x[0] == Approx(2.0)); // held out: twice the calibration's range
    CHECK((pts[2].x.tail(2) - pts[0].x.tail(2)).norm() == Approx(1.0));
    CHECK(pts[3].x.size() == 0);
}

TEST_CASE("noise shared by a curve's bins counts as one draw: the closed form of equicorrelated "
          "repeats",
          "[gap][discrepancy]") {
    // n residuals at one regime, all y, noise sd sigma with correlation c between any two:
    // their mean is sufficient, with noise variance v = sigma^2 (c + (1 - c) / n) (not
    // sigma^2 / n), so at that regime mean = s^2 y / (s^2 + v), variance = s^2 - s^4 / (s^2 + v).
    const int n = 10;
    const double y = 0.3, sigma = 0.1;
    std::vector<RegimePoint> pts(n, at("plate", 0.2));
    const Eigen::VectorXd rho = Eigen::VectorXd::Constant(n, y);
    const Eigen::VectorXd sd = Eigen::VectorXd::Constant(n, sigma);
    for (double c : {0.0, 0.5, 0.8}) {
        Eigen::MatrixXd corr = Eigen::MatrixXd::Constant(n, n, c);
        corr.diagonal().setOnes();
        const auto d = Discrepancy::fit(pts, rho, sd, corr);
        const double s2 = std::pow(d.hyperparameters().at("plate").sd, 2);
        const double v = sigma * sigma * (c + (1.0 - c) / n);
        const auto p = d.predict({at("plate", 0.2)});
        INFO("c = " << c << ", s = " << std::sqrt(s2));
        REQUIRE(s2 > 0.0);
        CHECK(p.mean[0] == Approx(s2 * y / (s2 + v)).epsilon(1e-9));
        CHECK(p.variance[0] == Approx(s2 - s2 * s2 / (s2 + v)).epsilon(1e-6));
    }
    // The correlation is the noise's own: an empty matrix is independent noise.
    const auto independent = Discrepancy::fit(pts, rho, sd).predict({at("plate", 0.2)});
    Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n, n);
    const auto same = Discrepancy::fit(pts, rho, sd, identity).predict({at("plate", 0.2)});
    CHECK(independent.mean[0] == Approx(same.mean[0]).epsilon(1e-12));
}
