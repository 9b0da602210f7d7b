#pragma once
// Fixed-point acceleration for implicit coupling: given the wrenches x the multibody side used and
// the wrenches H(x) the soil side returned, propose the next x (docs/protocol.md §Implicit).
#include <Eigen/Core>

#include <deque>
#include <memory>
#include <string>

namespace grainlink::coupling {

enum class AccelerationKind { Constant, Aitken, IqnIls };

struct AccelerationSettings {
    AccelerationKind kind = AccelerationKind::IqnIls;
    double initial_relaxation = 0.5; ///< ω of the first iteration of every window (and of Constant)
    unsigned reuse_windows = 0;      ///< IQN-ILS: keep the secant pairs of this many past windows
    double filter_epsilon = 1e-10;   ///< IQN-ILS: drop columns whose QR diagonal is below ε·|R|
};

class Acceleration {
public:
    virtual ~Acceleration() = default;
    /// Starts a window: forgets this window's iterates (IQN-ILS may keep older windows' pairs).
    virtual void beginWindow() = 0;
    /// Next input from the input `x` of this iteration and the output `h` = H(x).
    virtual Eigen::VectorXd next(const Eigen::VectorXd &x, const Eigen::VectorXd &h) = 0;
    /// The relaxation factor used in the last update (Aitken / Constant; NaN for IQN-ILS).
    virtual double lastRelaxation() const = 0;
};

std::unique_ptr<Acceleration> makeAcceleration(const AccelerationSettings &settings);
AccelerationKind accelerationFromName(const std::string &name); ///< constant|aitken|iqn-ils
const char *accelerationName(AccelerationKind kind);

} // namespace grainlink::coupling
