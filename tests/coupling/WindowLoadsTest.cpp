// The soil side's window sums: impulse, angular impulse and work over the sub-steps, and the
// window-averaged wrench J / H (docs/physics.md §7.1, §7.4), against the integrals in closed form.
#include "grainlink/coupling/WindowLoads.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::coupling;

TEST_CASE("Window loads: the wrench is the impulse over the window, the work F.v + T.w summed",
          "[coupling][loads]") {
    // Body "wheel": F(t) = F0 + F1 t and T(t) = T0 sampled at the midpoints of 40 sub-steps of a
    // 2 ms window (the rigid floor's scheme); the wheel moves at constant v and w. The midpoint
    // rule is exact for a linear force: J = F0 H + F1 H^2 / 2, so F = F0 + F1 H / 2, and
    // W = v . J + w . T0 H.
    const double H = 0.002;
    const int n = 40;
    const Vec3 F0(1.5, -0.25, 30.0), F1(100.0, 0.0, -2000.0), T0(0.0, 0.4, 0.01);
    const Vec3 v(0.3, 0.0, -0.02), w(0.0, 3.0, 0.0);
    WindowLoads loads({"wheel", "hull"});
    for (int k = 0; k < n; ++k) {
        const double t = (k + 0.5) * H / n;
        loads.add(0, F0 + F1 * t, T0, v, w, H / n);
    }
    // Body "hull": a model that integrated the window itself hands in its totals.
    const Vec3 J(0.01, 0.0, 0.05), L(0.0, -0.002, 0.0);
    loads.addTotals(1, J, L, 0.25);

    const WindowOutputs out = loads.outputs(H);
    REQUIRE(out.wrenches.size() == 2);
    REQUIRE(out.work.size() == 2);
    CHECK(out.wrenches[0].body == "wheel");
    CHECK(out.work[0].body == "wheel");
    CHECK(out.wrenches[1].body == "hull");
    const Vec3 mean = F0 + F1 * (H / 2);
    CHECK((out.wrenches[0].force_N - mean).norm() <= 1e-12 * mean.norm());
    CHECK((out.wrenches[0].torque_N_m - T0).norm() <= 1e-12 * T0.norm());
    const double work = v.dot(F0 * H + F1 * (H * H / 2)) + w.dot(T0) * H;
    CHECK(out.work[0].work_J == Approx(work).epsilon(1e-12));
    // Totals are averaged the same way, exactly.
    CHECK(out.wrenches[1].force_N == J / H);
    CHECK(out.wrenches[1].torque_N_m == L / H);
    CHECK(out.work[1].work_J == 0.25);
    // The outputs carry loads only: no states, no hint, the run goes on.
    CHECK(out.states.empty());
    CHECK(out.suggested_macro_step_s == 0.0);
    CHECK_FALSE(out.run_complete);

    CHECK_THROWS_WITH(loads.outputs(0.0), Catch::Contains("positive duration"));
    CHECK_THROWS_AS(loads.add(2, F0, T0, v, w, H), std::out_of_range);
}
