// The coupling guard (coupling/CouplingGuard) on window sequences whose answer is known by hand.
#include "grainlink/coupling/CouplingGuard.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace grainlink::coupling;

namespace {

std::vector<Wrench> force(double fx) {
    Wrench w;
    w.body = "wheel";
    w.force_N = Vec3(fx, 0.0, 10.0);
    return {w};
}

} // namespace

TEST_CASE("coupling guard: lag-1 autocorrelation", "[coupling][guard]") {
    // ±1 alternating, n values about mean 0: Σ x_k x_{k-1} = -(n - 1), Σ x² = n.
    std::vector<double> alternating;
    for (int k = 0; k < 10; ++k)
        alternating.push_back(k % 2 ? 1.0 : -1.0);
    CHECK(lagOneAutocorrelation(alternating) == Approx(-0.9));
    // A constant has no oscillation; 1, 2, 3, 4 about 2.5: (-1.5·-0.5 + -0.5·0.5 + 0.5·1.5)/5.
    CHECK(lagOneAutocorrelation(std::vector<double>(10, 3.0)) == 0.0);
    CHECK(lagOneAutocorrelation({1, 2, 3, 4}) == Approx(1.25 / 5.0));
}

TEST_CASE("coupling guard: energy mismatch past the threshold warns once", "[coupling][guard]") {
    GuardSettings settings;
    settings.span_windows = 10;
    // Soil work 0.1 J per window; mismatch 1 % of it: never a warning.
    CouplingGuard quiet(settings);
    for (int k = 0; k < 100; ++k)
        CHECK_FALSE(quiet.afterWindow(0.101, 0.1, force(1.0), 1e-3));
    // Mismatch 10 %: a warning once the span is full, once; the advice scales the macro step
    // to the 5 % threshold with a 0.8 margin: 1 ms x 0.8 x 5/10 = 0.4 ms.
    CouplingGuard loud(settings);
    int warnings = 0;
    for (int k = 0; k < 100; ++k)
        if (const auto w = loud.afterWindow(0.11, 0.1, force(1.0), 1e-3)) {
            ++warnings;
            CHECK(k == 9);
            CHECK(w->kind == GuardWarning::Kind::Energy);
            CHECK(w->measured == Approx(0.1));
            CHECK(w->suggested_step_s == Approx(0.4e-3));
            CHECK(w->message ==
                  "the energy mismatch over the last 10 windows, 0.1 J, is 10.0 % of the 1 J the "
                  "soil exchanged with the bodies (threshold 5 %, coupling.guard.energy_ratio): "
                  "the macro step 0.001 s is too long for these contacts; about 0.0004 s should "
                  "bring it under the threshold");
        }
    CHECK(warnings == 1);
    // After a change of step the span starts over and may warn again.
    loud.restart();
    for (int k = 0; k < 10; ++k)
        warnings += bool(loud.afterWindow(0.11, 0.1, force(1.0), 1e-3));
    CHECK(warnings == 2);
    // A quiet span after a busy one is judged against the run's mean exchange per span: the
    // body at rest (soil work 1e-6 J per window, mismatch 1e-7 J) is not "10 %".
    CouplingGuard resting(settings);
    int resting_warnings = 0;
    for (int k = 0; k < 10; ++k)
        resting_warnings += bool(resting.afterWindow(0.101, 0.1, force(1.0), 1e-3));
    for (int k = 0; k < 90; ++k)
        resting_warnings += bool(resting.afterWindow(1.1e-6, 1e-6, force(1.0), 1e-3));
    CHECK(resting_warnings == 0);
}

TEST_CASE("coupling guard: a force flipping every window warns", "[coupling][guard]") {
    GuardSettings settings;
    settings.span_windows = 200;
    // Alternating about 5 N: autocorrelation -(n-1)/n. White noise (about 0) and a slow sine
    // (about cos(2π/50) = 0.99) stay quiet.
    CouplingGuard flipping(settings), noisy(settings), smooth(settings);
    std::mt19937 random(3);
    std::normal_distribution<double> normal;
    int flips = 0, others = 0;
    for (int k = 0; k < 400; ++k) {
        if (const auto w = flipping.afterWindow(0.1, 0.1, force(5.0 + (k % 2 ? 2.0 : -2.0)), 1e-3)) {
            ++flips;
            CHECK(w->kind == GuardWarning::Kind::Oscillation);
            CHECK(w->measured == Approx(-199.0 / 200.0));
            CHECK(w->suggested_step_s == Approx(0.5e-3));
            CHECK(w->message.rfind("the soil's force on body 'wheel' (x) flips from window to "
                                   "window: lag-1 autocorrelation -0.99",
                                   0) == 0);
        }
        others += bool(noisy.afterWindow(0.1, 0.1, force(5.0 + normal(random)), 1e-3));
        others += bool(smooth.afterWindow(0.1, 0.1, force(5.0 + std::sin(2 * M_PI * k / 50)), 1e-3));
    }
    CHECK(flips == 1);
    CHECK(others == 0);
    // Switched off, nothing is judged.
    settings.enabled = false;
    CouplingGuard off(settings);
    for (int k = 0; k < 400; ++k)
        CHECK_FALSE(off.afterWindow(1.0, 0.1, force(k % 2 ? 1.0 : -1.0), 1e-3));
}
