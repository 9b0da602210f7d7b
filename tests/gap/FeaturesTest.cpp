#include "grainlink/gap/Features.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace grainlink::gap;

namespace {
Curve sampled(double (*f)(double), double a, double b, int n) {
    Curve c;
    for (int i = 0; i <= n; ++i) {
        const double x = a + (b - a) * i / n;
        c.x.push_back(x);
        c.y.push_back(f(x));
    }
    return c;
}
} // namespace

TEST_CASE("a bin mean is the integral of the curve over the bin divided by its width",
          "[gap][features]") {
    // y = x^2: the mean over [a, b] is (b^3 - a^3) / (3 (b - a)); the trapezoid rule with
    // h = 1e-3 errs by h^2 f'' / 12 = 1.7e-7 (1.3e-6 relative).
    const Curve c = sampled([](double x) { return x * x; }, 0.0, 1.0, 1000);
    const double a = 0.2, b = 0.5;
    REQUIRE(binMean(c, a, b).has_value());
    CHECK(*binMean(c, a, b) == Approx((b * b * b - a * a * a) / (3.0 * (b - a))).epsilon(2e-6));
    // A linear curve's bin mean is exact, even with the bin edges between samples.
    const Curve line{{0.0, 0.3, 1.0}, {1.0, 1.6, 3.0}};
    CHECK(*binMean(line, 0.1, 0.9) == Approx(1.0 + 2.0 * 0.5).epsilon(1e-12));
}

TEST_CASE("a bin the curve does not cover has no mean, a scalar is its own value",
          "[gap][features]") {
    const Curve c{{0.0, 0.01}, {0.0, 1.0}};
    CHECK_FALSE(binMean(c, 0.005, 0.02).has_value());
    CHECK_FALSE(binMean(c, -0.001, 0.005).has_value());
    CHECK(*binMean(Curve{{0.0}, {31.5}}, 0.0, 0.0) == 31.5);
    // A recording whose first sample lies a little into the first bin (the CMU plates: 0.22 mm
    // of 2.5 mm) covers it, held at its first value back to the bin's start; p = z from 0.2:
    // (0.2 * 0.2 + (2.5^2 - 0.2^2) / 2) / 2.5 = 1.258, against 1.25 from 0.
    const Curve late{{0.2, 2.5}, {0.2, 2.5}};
    REQUIRE(binMean(late, 0.0, 2.5).has_value());
    CHECK(*binMean(late, 0.0, 2.5) == Approx(1.258).epsilon(1e-9));
    CHECK_FALSE(binMean(Curve{{0.3, 2.5}, {0.3, 2.5}}, 0.0, 2.5).has_value()); // 12 % in
    // A curve cut to one sample is no curve: it gave its value to every bin.
    CHECK_FALSE(binMean(Curve{{0.004}, {31.5}}, 0.0, 0.002).has_value());
}

TEST_CASE("bin edges have a round width", "[gap][features]") {
    const auto e = roundBinEdges(0.0, 0.02, 6); // 3.33 mm raw -> 2.5 mm, 8 of them to 20 mm
    REQUIRE(e.size() == 9);
    CHECK(e[1] == Approx(0.0025));
    CHECK(e.back() == Approx(0.02));
    const auto f = roundBinEdges(1.0, 2.0, 5); // 0.2 exactly
    CHECK(f[1] == Approx(1.2));
    // Runs scattered to 0.75: 0.1 wide, to 0.7 before the end, to 0.8 to cover it.
    CHECK(roundBinEdges(0.0, 0.75, 6).back() == Approx(0.7));
    CHECK(roundBinEdges(0.0, 0.75, 6, true).back() == Approx(0.8));
    CHECK(roundBinEdges(1.0, 2.0, 5, true).back() == Approx(2.0)); // an end on an edge: no more
}

TEST_CASE("feature rows and their column statistics skip what a curve does not reach",
          "[gap][features]") {
    const std::vector<Curve> curves{{{0.0, 2.0}, {0.0, 2.0}}, {{0.0, 1.0}, {0.0, 2.0}}};
    const Eigen::MatrixXd rows = featureRows(curves, {0.0, 1.0, 2.0});
    CHECK(rows(0, 0) == Approx(0.5));
    CHECK(rows(1, 0) == Approx(1.0));
    CHECK(std::isnan(rows(1, 1)));
    const ColumnStats s = columnStats(rows);
    CHECK(s.mean[0] == Approx(0.75));
    CHECK(s.sd[0] == Approx(std::sqrt(0.125)));
    CHECK(s.count[1] == 1);
    CHECK(s.mean[1] == Approx(1.5));
    CHECK(std::isnan(s.sd[1]));
}

TEST_CASE("pooled scatter: squared deviations from each group's mean over their degrees of freedom",
          "[gap][features]") {
    // Two groups of one column: {1, 3} (mean 2, squares 2, 1 dof) and {10, 13, 16} (mean 13,
    // squares 18, 2 dof): pooled variance 20 / 3. A second column with one value per group has no
    // degrees of freedom and keeps the fallback.
    Eigen::MatrixXd a(2, 2), b(3, 2);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    a << 1, 5, 3, nan;
    b << 10, 7, 13, nan, 16, nan;
    PooledScatter pool(2);
    pool.add(a);
    pool.add(b);
    const Eigen::VectorXd sd = pool.sd(Eigen::Vector2d(-1.0, -2.0));
    CHECK(sd[0] == Approx(std::sqrt(20.0 / 3.0)));
    CHECK(pool.dof()[0] == 3);
    CHECK(sd[1] == -2.0);
    CHECK(pool.dof()[1] == 0);
}

TEST_CASE("pooled scatter with few degrees of freedom takes its experiment's median relative "
          "scatter",
          "[gap][features]") {
    // One group of two seeds over four features: experiment "a" has three features with sample
    // sds 1, 4, 30 at reference values 10, 20, 100 (relative 0.1, 0.2, 0.3: median 0.2);
    // experiment "b" one feature with no second value. With min_dof 2 (one dof here) each of
    // a's features becomes 0.2 x |reference| (2, 4, 20); b keeps the fallback. With min_dof 1
    // nothing changes.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Eigen::MatrixXd g(2, 4);
    const double s2 = std::sqrt(2.0); // two values x +- d/2 have sample sd d / sqrt 2
    g << 10, 20, 100, 5,              //
        10 + 1 * s2, 20 + 4 * s2, 100 + 30 * s2, nan;
    PooledScatter pool(4);
    pool.add(g);
    const Eigen::Vector4d reference(10, 20, 100, 5);
    const std::vector<std::string> groups{"a", "a", "a", "b"};
    const Eigen::Vector4d fallback(-1, -2, -3, -4);
    const Eigen::VectorXd few = pool.sd(fallback, reference, groups, 2);
    CHECK(few[0] == Approx(2.0));
    CHECK(few[1] == Approx(4.0));
    CHECK(few[2] == Approx(20.0));
    CHECK(few[3] == -4.0);
    const Eigen::VectorXd enough = pool.sd(fallback, reference, groups, 1);
    CHECK(enough[0] == Approx(1.0));
    CHECK(enough[1] == Approx(4.0));
    CHECK(enough[2] == Approx(30.0));
}
