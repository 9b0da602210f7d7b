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
        CHECK_FALSE(quiet.afterWindow(0.101, 0.1, force(1.0), {}, 1e-3));
    // Mismatch 10 %: a warning once the span is full, once; the advice scales the macro step
    // to the 5 % threshold with a 0.8 margin: 1 ms x 0.8 x 5/10 = 0.4 ms.
    CouplingGuard loud(settings);
    int warnings = 0;
    for (int k = 0; k < 100; ++k)
        if (const auto w = loud.afterWindow(0.11, 0.1, force(1.0), {}, 1e-3)) {
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
        warnings += bool(loud.afterWindow(0.11, 0.1, force(1.0), {}, 1e-3));
    CHECK(warnings == 2);
    // A quiet span after a busy one is judged against the run's mean exchange per span: the
    // body at rest (soil work 1e-6 J per window, mismatch 1e-7 J) is not "10 %".
    CouplingGuard resting(settings);
    int resting_warnings = 0;
    for (int k = 0; k < 10; ++k)
        resting_warnings += bool(resting.afterWindow(0.101, 0.1, force(1.0), {}, 1e-3));
    for (int k = 0; k < 90; ++k)
        resting_warnings += bool(resting.afterWindow(1.1e-6, 1e-6, force(1.0), {}, 1e-3));
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
        if (const auto w =
                flipping.afterWindow(0.1, 0.1, force(5.0 + (k % 2 ? 2.0 : -2.0)), {}, 1e-3)) {
            ++flips;
            CHECK(w->kind == GuardWarning::Kind::Oscillation);
            CHECK(w->measured == Approx(-199.0 / 200.0));
            CHECK(w->suggested_step_s == Approx(0.5e-3));
            CHECK(w->message.rfind("the soil's force on body 'wheel' (x) flips from window to "
                                   "window: lag-1 autocorrelation -0.99",
                                   0) == 0);
        }
        others += bool(noisy.afterWindow(0.1, 0.1, force(5.0 + normal(random)), {}, 1e-3));
        others +=
            bool(smooth.afterWindow(0.1, 0.1, force(5.0 + std::sin(2 * M_PI * k / 50)), {}, 1e-3));
    }
    CHECK(flips == 1);
    CHECK(others == 0);
    // Switched off, nothing is judged.
    settings.enabled = false;
    CouplingGuard off(settings);
    for (int k = 0; k < 400; ++k)
        CHECK_FALSE(off.afterWindow(1.0, 0.1, force(k % 2 ? 1.0 : -1.0), {}, 1e-3));
}

namespace {

// A wheel bouncing vertically at 8 Hz (125 windows of 1 ms a period): height A sin ωt, the soil's
// vertical force F0 − k A sin ωt. Over whole periods the fluctuating force does
// Σ |k A sin · A ω cos| H = k A² ω H Σ |sin cos| ≈ k A² ω H n / π on the fluctuating motion.
struct Bounce {
    double amplitude_m = 1e-3, stiffness_N_m = 8000.0, omega = 2 * M_PI * 8.0, step_s = 1e-3;
    double decay_per_s = 0.0;
    std::vector<Wrench> wrench(int k) const {
        Wrench w;
        w.body = "wheel";
        w.force_N = Vec3(0.0, 0.0, 30.0 - stiffness_N_m * height(k));
        return {w};
    }
    std::vector<BodyState> state(int k) const {
        BodyState s;
        s.body = "wheel";
        const double t = k * step_s;
        s.linear_velocity_m_s.z() =
            amplitude_m * std::exp(-decay_per_s * t) *
            (omega * std::cos(omega * t) - decay_per_s * std::sin(omega * t));
        return {s};
    }
    double height(int k) const {
        const double t = k * step_s;
        return amplitude_m * std::exp(-decay_per_s * t) * std::sin(omega * t);
    }
    /// The work of the fluctuation over a span of n windows, by the closed form above.
    double spanWork(int n) const {
        return stiffness_N_m * amplitude_m * amplitude_m * omega * step_s * n / M_PI;
    }
};

} // namespace

TEST_CASE("coupling guard: a bounce the coupling feeds warns and one dying down does not",
          "[coupling][guard]") {
    GuardSettings settings; // span 500 windows, share 6 %, 3 spans
    const Bounce bounce;
    const double work = bounce.spanWork(500); // 0.064 J
    // The coupling creates 8 % of it per span, spread evenly; the soil's work 0.1 J a window
    // keeps the energy check (1e-4 of it) quiet.
    const double feeding = 0.08 * work / 500;
    CouplingGuard fed(settings);
    int warnings = 0;
    for (int k = 0; k < 3000; ++k)
        if (const auto w =
                fed.afterWindow(0.1 + feeding, 0.1, bounce.wrench(k), bounce.state(k), 1e-3)) {
            ++warnings;
            CHECK(k == 1499); // the third span in a row
            CHECK(w->kind == GuardWarning::Kind::Bounce);
            CHECK(w->measured == Approx(0.08).epsilon(0.01));
            CHECK(w->suggested_step_s == Approx(0.8e-3 * 0.06 / 0.08).epsilon(0.01));
            CHECK(w->message.rfind("the coupling feeds a bounce: for 3 spans of 500 windows it "
                                   "created 8.0 %",
                                   0) == 0);
        }
    CHECK(warnings == 1);

    // With the soil's work only 1e-4 J a window the same created energy is 10 % of it: the
    // energy check warns at the first span's end, and the bounce is still judged on that span,
    // so it warns at the third, not a span late.
    CouplingGuard both(settings);
    std::vector<int> at;
    std::vector<GuardWarning::Kind> kinds;
    for (int k = 0; k < 3000; ++k)
        if (const auto w = both.afterWindow(1e-4 + feeding, 1e-4, bounce.wrench(k),
                                            bounce.state(k), 1e-3)) {
            at.push_back(k);
            kinds.push_back(w->kind);
        }
    CHECK(at == std::vector<int>{499, 1499});
    CHECK(kinds == std::vector<GuardWarning::Kind>{GuardWarning::Kind::Energy,
                                                   GuardWarning::Kind::Bounce});

    // Half of it (4 %): quiet. 8 % for two spans, then 4 %: quiet (it must persist).
    CouplingGuard half(settings), brief(settings);
    int others = 0;
    for (int k = 0; k < 3000; ++k) {
        others +=
            bool(half.afterWindow(0.1 + feeding / 2, 0.1, bounce.wrench(k), bounce.state(k), 1e-3));
        others += bool(brief.afterWindow(0.1 + (k < 1000 ? feeding : feeding / 2), 0.1,
                                         bounce.wrench(k), bounce.state(k), 1e-3));
    }
    CHECK(others == 0);

    // A bounce dying down (amplitude e^(−3t): its work falls by e^(−2) over a span's two thirds)
    // is damped by the soil whatever the coupling creates: quiet, while the same created energy
    // on the steady bounce (8 %) warns above.
    Bounce dying = bounce;
    dying.decay_per_s = 3.0;
    CouplingGuard damped(settings);
    for (int k = 0; k < 3000; ++k)
        others +=
            bool(damped.afterWindow(0.1 + feeding, 0.1, dying.wrench(k), dying.state(k), 1e-3));
    CHECK(others == 0);
}
