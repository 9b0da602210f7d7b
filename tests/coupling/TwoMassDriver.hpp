#pragma once
// Runs the two-mass example through a CouplingScheme in one process, window by window, exactly
// as the coordinator would — the reference the networked runs are compared with.
#include "TwoMassModel.hpp"
#include "grainlink/coupling/CouplingScheme.hpp"

#include <algorithm>
#include <cmath>

namespace grainlink::testing {

struct TwoMassRun {
    double max_error_m = 0.0; ///< max over windows of |x1 - x1_monolithic|
    double final_x1_m = 0.0;
    unsigned max_iterations = 0; ///< implicit: most passes any window needed
    unsigned total_iterations = 0;
    double work_mismatch_J = 0.0; ///< sum over windows of multibody work - soil work
};

inline TwoMassRun runTwoMass(const coupling::SchemeSettings &settings, double window_s,
                             double end_s, const examples::TwoMassParameters &p = {}) {
    examples::MassOneSide one(p);
    examples::MassTwoSide two(p);
    coupling::CouplingScheme scheme(settings, {one.state()});
    TwoMassRun run;
    const auto windows = static_cast<unsigned>(std::lround(end_s / window_s));
    for (unsigned k = 0; k < windows; ++k) {
        scheme.beginWindow(window_s);
        double work_one = 0.0, work_two = 0.0;
        for (auto tasks = scheme.tasks(); !tasks.empty(); tasks = scheme.tasks()) {
            for (const auto &task : tasks) {
                if (task.role == coupling::Role::Multibody) {
                    if (task.restore_state)
                        one.restore();
                    if (task.save_state)
                        one.save();
                    work_one = one.advance(window_s, task.wrenches[0].force_N.x());
                    scheme.completeMultibody({one.state()});
                } else {
                    if (task.restore_state)
                        two.restore();
                    if (task.save_state)
                        two.save();
                    const auto &a = task.start_states[0], &b = task.end_states[0];
                    const auto r =
                        two.advance(window_s, a.position_m.x(), a.linear_velocity_m_s.x(),
                                    b.position_m.x(), b.linear_velocity_m_s.x());
                    work_two = r.work_on_mass1_J;
                    coupling::Wrench w;
                    w.body = "mass1";
                    w.force_N = coupling::Vec3(r.force_on_mass1_N, 0, 0);
                    scheme.completeSoil({w});
                }
            }
        }
        run.max_iterations = std::max(run.max_iterations, scheme.iterations());
        run.total_iterations += scheme.iterations();
        run.work_mismatch_J += work_one - work_two;
        const double exact = examples::monolithicTwoMass(p, (k + 1) * window_s)[0];
        const double error = std::abs(one.x() - exact);
        run.max_error_m = std::isfinite(one.x()) ? std::max(run.max_error_m, error) : INFINITY;
    }
    run.final_x1_m = one.x();
    return run;
}

} // namespace grainlink::testing
