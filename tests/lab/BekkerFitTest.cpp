// Bekker's pressure-sinkage law fitted by Levenberg-Marquardt, docs/physics.md §12.6.
#include "grainlink/lab/BekkerFit.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// Curves of the given plates from known parameters, with Gaussian noise of `noise_Pa`.
std::vector<lab::PressureSinkageCurve> synthetic(const lab::BekkerParameters &p,
                                                 std::vector<double> radii, double noise_Pa,
                                                 unsigned seed) {
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, noise_Pa);
    std::vector<lab::PressureSinkageCurve> curves;
    for (double b : radii) {
        lab::PressureSinkageCurve c;
        c.plate_radius_m = b;
        for (int i = 1; i <= 40; ++i) {
            const double z = 0.02 * i / 40.0;
            c.sinkage_m.push_back(z);
            c.pressure_Pa.push_back(p.pressure(b, z) + (noise_Pa > 0.0 ? noise(random) : 0.0));
        }
        curves.push_back(c);
    }
    return curves;
}

} // namespace

TEST_CASE("Student t quantile t(0.975, dof)", "[lab][bekker]") {
    // Table values (any statistics text); the expansion is good to 1e-3 from dof 5 on.
    CHECK(lab::studentT975(1) == Approx(12.706).epsilon(1e-4));
    CHECK(lab::studentT975(5) == Approx(2.5706).epsilon(1e-3));
    CHECK(lab::studentT975(10) == Approx(2.2281).epsilon(1e-4));
    CHECK(lab::studentT975(30) == Approx(2.0423).epsilon(1e-4));
    CHECK(lab::studentT975(1000) == Approx(1.9623).epsilon(1e-4));
}

TEST_CASE("Bekker fit recovers known parameters", "[lab][bekker]") {
    // A sand-like soil in the range of the seed's Figure 7: ~10-20 kPa at 20 mm.
    const lab::BekkerParameters truth{1500.0, 8.0e5, 0.9};

    SECTION("noise-free data: exact up to the solver tolerance") {
        const auto fit = lab::fitBekker(synthetic(truth, {0.02, 0.03, 0.05}, 0.0, 1));
        // The solver stops at relative 1e-14 steps; 1e-6 leaves room for the conditioning.
        CHECK(fit.parameters.k_c == Approx(truth.k_c).epsilon(1e-6));
        CHECK(fit.parameters.k_phi == Approx(truth.k_phi).epsilon(1e-6));
        CHECK(fit.parameters.n == Approx(truth.n).epsilon(1e-6));
        CHECK(fit.rms_residual_Pa < 1e-6);
    }
    SECTION("noisy data: the 95 % intervals cover the truth about 95 % of the time") {
        // 200 Pa noise (~2 % of the largest pressure), 200 independent data sets. Per parameter
        // the number of misses is binomial(200, 0.05) if the intervals are right: mean 10,
        // sd 3.1; [2, 20] is beyond 2.5 sd either side. Intervals too wide give ~0 misses,
        // too narrow give many: both fail. The spread of the estimates must match the reported
        // standard errors within 15 % (the sampling error of an rms over 200 sets is ~5 %).
        const int sets = 200;
        Eigen::Vector3i misses = Eigen::Vector3i::Zero();
        Eigen::Vector3d error_sq = Eigen::Vector3d::Zero(), se = Eigen::Vector3d::Zero();
        const Eigen::Vector3d tru(truth.k_c, truth.k_phi, truth.n);
        for (unsigned seed = 1; seed <= unsigned(sets); ++seed) {
            const auto fit = lab::fitBekker(synthetic(truth, {0.02, 0.03, 0.05}, 200.0, seed));
            const Eigen::Vector3d est(fit.parameters.k_c, fit.parameters.k_phi, fit.parameters.n);
            for (int k = 0; k < 3; ++k) {
                misses[k] += std::abs(est[k] - tru[k]) > fit.half_width_95[k];
                error_sq[k] += (est[k] - tru[k]) * (est[k] - tru[k]) / sets;
                se[k] += fit.standard_error[k] / sets;
            }
            if (seed == 1)
                WARN(fit.describe());
        }
        for (int k = 0; k < 3; ++k) {
            INFO("parameter " << k << " (k_c, k_phi, n): misses " << misses[k] << "/" << sets
                              << ", rms error " << std::sqrt(error_sq[k]) << ", mean SE " << se[k]);
            CHECK(misses[k] >= 2);
            CHECK(misses[k] <= 20);
            CHECK(std::sqrt(error_sq[k]) == Approx(se[k]).epsilon(0.15));
        }
    }
}

TEST_CASE("Bekker fit refuses data that cannot separate k_c and k_phi", "[lab][bekker]") {
    const lab::BekkerParameters truth{1500.0, 8.0e5, 0.9};
    CHECK_THROWS_WITH(lab::fitBekker(synthetic(truth, {0.03}, 0.0, 1)),
                      Contains("two plate radii"));
    CHECK_THROWS_WITH(lab::fitBekker(synthetic(truth, {0.03, 0.05}, 0.0, 1), 0.1),
                      Contains("two plate radii"));
}
