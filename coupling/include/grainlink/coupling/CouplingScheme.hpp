#pragma once
// Which participant advances when, on which inputs, and when a window is accepted. Transport-free,
// so it can be driven window by window in tests (docs/protocol.md §Schemes).
#include "grainlink/coupling/Acceleration.hpp"
#include "grainlink/coupling/Types.hpp"

#include <memory>
#include <vector>

namespace grainlink::coupling {

struct SchemeSettings {
    SchemeKind kind = SchemeKind::ExplicitSerial;
    double relative_tolerance = 1e-6; ///< implicit: |H(x) - x| <= rel |H(x)| + abs
    double absolute_tolerance = 1e-9; ///< [N, N m] implicit
    unsigned max_iterations = 50;     ///< implicit: a window that needs more is an error
    AccelerationSettings acceleration;
};

/// One role's job inside the current window.
struct Task {
    Role role = Role::Multibody;
    unsigned iteration = 0;
    bool save_state = false;             ///< save the state at the window start before advancing
    bool restore_state = false;          ///< roll back to the saved state before advancing
    std::vector<Wrench> wrenches;        ///< multibody input: applied over the whole window
    std::vector<BodyState> start_states; ///< soil input: body states at the window start
    std::vector<BodyState> end_states;   ///< soil input: body states at the window end
};

class CouplingScheme {
public:
    /// `initial` are the body states at the run start; wrenches start at zero. Bodies keep this
    /// order.
    CouplingScheme(const SchemeSettings &settings, std::vector<BodyState> initial);

    /// Restores the scheme at a window boundary (resume from a checkpoint).
    void restore(std::vector<BodyState> states, std::vector<Wrench> wrenches);

    void beginWindow(double window_s);
    /// What must run now, all of it concurrently; empty once the window is accepted.
    std::vector<Task> tasks() const;
    /// The same into `out`, reusing its storage: no allocation per call once warm.
    void tasks(std::vector<Task> &out) const;
    void completeMultibody(const std::vector<BodyState> &end_states);
    void completeSoil(const std::vector<Wrench> &wrenches);

    bool accepted() const { return stage_ == Stage::Accepted; }
    unsigned iterations() const { return iteration_ + 1; } ///< passes over the current window
    double residual() const { return residual_; }          ///< implicit: last |H(x) - x| / |H(x)|
    /// States at the start of the current window, or at its end once it is accepted.
    const std::vector<BodyState> &states() const { return states_; }
    /// The last accepted window's wrenches (zero before the first).
    const std::vector<Wrench> &wrenches() const { return wrenches_; }
    const SchemeSettings &settings() const { return settings_; }

private:
    enum class Stage { Multibody, Soil, Both, Accepted };
    /// `states` (or `wrenches`) in body order into `out`; throws on a missing or unknown body.
    void order(const std::vector<BodyState> &states, std::vector<BodyState> &out);
    void order(const std::vector<Wrench> &wrenches, std::vector<Wrench> &out);
    std::vector<BodyState> extrapolated(double window_s) const;
    void finishIteration(const std::vector<Wrench> &soil_wrenches);

    SchemeSettings settings_;
    std::vector<std::string> bodies_;
    std::unique_ptr<Acceleration> acceleration_;
    Stage stage_ = Stage::Accepted;
    unsigned iteration_ = 0;
    double residual_ = 0.0;
    bool multibody_done_ = false, soil_done_ = false;
    std::vector<BodyState> states_;      ///< accepted states (window start, then end)
    std::vector<BodyState> end_states_;  ///< this iteration's multibody result
    std::vector<BodyState> soil_inputs_; ///< the end states the soil side gets
    std::vector<Wrench> wrenches_;       ///< accepted wrenches of the last window
    std::vector<Wrench> applied_;        ///< what the multibody side applies this iteration
    std::vector<Wrench> soil_result_;
    std::vector<BodyState> scratch_states_; ///< reused by completeMultibody()
    std::vector<Wrench> scratch_wrenches_;  ///< reused by completeSoil()
    std::vector<char> seen_;                ///< scratch of order()
};

/// Wrenches as one vector (force, torque per body) for the fixed-point iteration.
Eigen::VectorXd stack(const std::vector<Wrench> &wrenches);
void unstack(const Eigen::VectorXd &values, std::vector<Wrench> &wrenches);

} // namespace grainlink::coupling
