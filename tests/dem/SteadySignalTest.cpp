// The steady-signal statistics (dem/SteadySignal) against references they do not compute
// themselves: the coverage of their 95 % intervals on signals with a known mean and trend, and
// Student's t density integrated numerically.
#include "grainlink/dem/SteadySignal.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace grainlink::dem;

namespace {

/// n samples of an AR(1) process x_k = φ x_{k-1} + e_k with unit innovations, from stationarity:
/// its integrated correlation time is (1 + φ)/(1 - φ) samples, the kind of memory a coupled run's
/// windows have.
std::vector<double> ar1(std::mt19937 &random, std::size_t n, double phi) {
    std::normal_distribution<double> normal;
    std::vector<double> x(n);
    x[0] = normal(random) / std::sqrt(1.0 - phi * phi);
    for (std::size_t k = 1; k < n; ++k)
        x[k] = phi * x[k - 1] + normal(random);
    return x;
}

} // namespace

TEST_CASE("steady signal: batch-means intervals cover", "[dem][statistics]") {
    // AR(1) with φ = 0.95 (correlation time 39 samples), 2000 samples, 400 realisations: the
    // mean's interval ± t(9)·se covers the true mean 0 in 95 % of them (binomial sd 1.1 %;
    // accepted 90-99 %), where the naive sd/√n interval covers about a quarter.
    std::mt19937 random(7);
    int covered = 0, naive_covered = 0;
    const int realisations = 400;
    for (int r = 0; r < realisations; ++r) {
        const auto x = ar1(random, 2000, 0.95);
        const auto s = summarizeSignal(x, 10);
        REQUIRE(s.batches == 10);
        covered += std::abs(s.mean) <= studentT95(9) * s.standard_error;
        naive_covered += std::abs(s.mean) <= 1.96 * s.sd / std::sqrt(2000.0);
    }
    CHECK(covered >= 0.90 * realisations);
    CHECK(covered <= 0.99 * realisations);
    CHECK(naive_covered < 0.5 * realisations);

    // A trend of 0.3 per second over 2 s plus the same noise: the slope's interval covers 0.3
    // in about 95 % of realisations; a flat signal is consistent with zero about as often.
    int slope_covered = 0, flat_consistent = 0, steep_detected = 0;
    for (int r = 0; r < realisations; ++r) {
        const auto noise = ar1(random, 2000, 0.95);
        std::vector<double> t(2000), rising(2000), steep(2000);
        for (std::size_t k = 0; k < t.size(); ++k) {
            t[k] = 1e-3 * double(k);
            rising[k] = 0.3 * t[k] + noise[k];
            steep[k] = 20.0 * t[k] + noise[k];
        }
        const auto trend = signalTrend(t, rising, 20);
        REQUIRE(trend.dof == 18);
        slope_covered += std::abs(trend.slope_per_s - 0.3) <= studentT95(18) * trend.slope_se_per_s;
        flat_consistent += signalTrend(t, noise, 20).consistentWithZero();
        steep_detected += !signalTrend(t, steep, 20).consistentWithZero();
    }
    CHECK(slope_covered >= 0.90 * realisations);
    CHECK(slope_covered <= 0.99 * realisations);
    CHECK(flat_consistent >= 0.90 * realisations);
    CHECK(flat_consistent <= 0.99 * realisations);
    // 20 per second over 2 s is a change of 40 against a noise sd of 3.2: always seen.
    CHECK(steep_detected == realisations);
}

TEST_CASE("steady signal: exact cases", "[dem][statistics]") {
    // A line through three points (0, 1), (1, 2), (2, 4): slope 1.5, mean 7/3 at x 1, residuals
    // (1/6, -1/3, 1/6): se = sqrt((1/6) / 1 / 2).
    const auto fit = fitLine({0, 1, 2}, {1, 2, 4});
    CHECK(fit.slope == Approx(1.5));
    CHECK(fit.intercept == Approx(7.0 / 3.0));
    CHECK(fit.x_mean == Approx(1.0));
    CHECK(fit.slope_se == Approx(std::sqrt(1.0 / 12.0)));
    CHECK(fit.dof == 1);
    CHECK(fitLine({1, 1, 1}, {0, 1, 2}).dof == 0);
    // A constant: no fluctuation, no error, no trend. A line: its slope exactly, zero error.
    const std::vector<double> t = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    std::vector<double> flat(10, 2.5), line(10);
    for (std::size_t k = 0; k < t.size(); ++k)
        line[k] = 1.0 - 0.5 * t[k];
    const auto s = summarizeSignal(flat, 5);
    CHECK(s.mean == Approx(2.5));
    CHECK(s.sd == Approx(0.0).margin(1e-15));
    CHECK(s.standard_error == Approx(0.0).margin(1e-15));
    const auto trend = signalTrend(t, line, 5);
    CHECK(trend.slope_per_s == Approx(-0.5));
    CHECK(trend.slope_se_per_s == Approx(0.0).margin(1e-12));
    CHECK_FALSE(trend.consistentWithZero());
    CHECK(signalTrend(t, flat, 5).consistentWithZero());
    // Fewer samples than batches: one batch per sample; two samples give no trend.
    CHECK(summarizeSignal({1.0, 3.0}, 10).batches == 2);
    CHECK(summarizeSignal({1.0, 3.0}, 10).standard_error == Approx(1.0));
    CHECK(signalTrend({0.0, 1.0}, {0.0, 5.0}).dof == 0);
    CHECK_THROWS_WITH(signalTrend({0.0}, {1.0, 2.0}), "signal trend: 1 times for 2 values");
}

TEST_CASE("steady signal: t quantiles integrate to 95 %", "[dem][statistics]") {
    // Student's t density, integrated by Simpson's rule from -q to q, holds 95 % (within 1e-6)
    // for the dof the steady-state and fit intervals use.
    for (std::size_t dof : {1, 2, 3, 5, 9, 18, 30, 100}) {
        const double nu = double(dof);
        const double norm = std::exp(std::lgamma((nu + 1) / 2) - std::lgamma(nu / 2)) /
                            std::sqrt(nu * M_PI);
        const auto density = [&](double x) {
            return norm * std::pow(1.0 + x * x / nu, -(nu + 1) / 2);
        };
        const double q = studentT95(dof);
        const int n = 20000;
        const double h = 2.0 * q / n;
        double integral = density(-q) + density(q);
        for (int k = 1; k < n; ++k)
            integral += (k % 2 ? 4.0 : 2.0) * density(-q + k * h);
        integral *= h / 3.0;
        INFO("dof " << dof);
        CHECK(integral == Approx(0.95).margin(1e-6));
    }
    CHECK_THROWS(studentT95(0));
}
