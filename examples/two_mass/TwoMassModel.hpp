#pragma once
// A two-mass spring-damper cut in two at the coupling spring: the smallest problem that has the
// structure of a wheel on soil. The multibody side owns mass 1 (spring k1 and damper c1 to
// ground) and applies the force it is given; the soil side owns mass 2 (spring k2 to ground) and
// the coupling spring-damper kc, cc, which it stretches by mass 1's prescribed motion and whose
// window-averaged force on mass 1 it returns. The monolithic solution is exact (matrix
// exponential).
#include "grainlink/coupling/Types.hpp"

#include <Eigen/Core>
#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <fstream>
#include <string>

namespace grainlink::examples {

struct TwoMassParameters {
    double m1_kg = 1.0, k1_N_m = 40.0, c1_N_s_m = 0.1;
    double m2_kg = 0.5, k2_N_m = 10.0;
    double kc_N_m = 200.0, cc_N_s_m = 0.5;
    double x1_initial_m = 0.1;
    double max_substep_s = 1e-4; ///< each side sub-cycles inside a window with RK4 steps this size
};

/// State (x1, v1, x2, v2) of the uncut system at time t, exactly.
inline Eigen::Vector4d monolithicTwoMass(const TwoMassParameters &p, double t) {
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    a(0, 1) = 1.0;
    a(1, 0) = -(p.k1_N_m + p.kc_N_m) / p.m1_kg;
    a(1, 1) = -(p.c1_N_s_m + p.cc_N_s_m) / p.m1_kg;
    a(1, 2) = p.kc_N_m / p.m1_kg;
    a(1, 3) = p.cc_N_s_m / p.m1_kg;
    a(2, 3) = 1.0;
    a(3, 0) = p.kc_N_m / p.m2_kg;
    a(3, 1) = p.cc_N_s_m / p.m2_kg;
    a(3, 2) = -(p.k2_N_m + p.kc_N_m) / p.m2_kg;
    a(3, 3) = -p.cc_N_s_m / p.m2_kg;
    const Eigen::Vector4d y0(p.x1_initial_m, 0.0, 0.0, 0.0);
    const Eigen::Matrix4d at = a * t;
    return at.exp() * y0;
}

/// Checkpoint of one side: position and velocity, round-trip exact at 17 digits.
inline void writeState(const std::string &path, double x, double v) {
    std::ofstream out(path);
    out.precision(17);
    out << x << ' ' << v << '\n';
    if (!out)
        throw coupling::CouplingError("cannot write checkpoint " + path);
}

inline void readState(const std::string &path, double &x, double &v) {
    std::ifstream in(path);
    if (!(in >> x >> v))
        throw coupling::CouplingError("cannot read checkpoint " + path);
}

inline unsigned substepsFor(double window_s, double max_substep_s) {
    return static_cast<unsigned>(std::ceil(window_s / max_substep_s - 1e-9));
}

/// Mass 1: integrates under a constant coupling force per window (RK4 sub-steps).
class MassOneSide {
public:
    explicit MassOneSide(const TwoMassParameters &p) : p_(p), x_(p.x1_initial_m) {}

    coupling::BodyDescription body() const {
        coupling::BodyDescription b;
        b.name = "mass1";
        b.mass.mass_kg = p_.m1_kg;
        return b;
    }
    coupling::BodyState state() const {
        coupling::BodyState s;
        s.body = "mass1";
        s.position_m = coupling::Vec3(x_, 0, 0);
        s.linear_velocity_m_s = coupling::Vec3(v_, 0, 0);
        return s;
    }
    /// Advances by `window_s` under force_N; returns the work that force did [J].
    double advance(double window_s, double force_N) {
        const double x0 = x_;
        const unsigned n = substepsFor(window_s, p_.max_substep_s);
        const double h = window_s / n;
        auto accel = [&](double x, double v) {
            return (force_N - p_.k1_N_m * x - p_.c1_N_s_m * v) / p_.m1_kg;
        };
        for (unsigned i = 0; i < n; ++i) {
            const double k1x = v_, k1v = accel(x_, v_);
            const double k2x = v_ + 0.5 * h * k1v, k2v = accel(x_ + 0.5 * h * k1x, k2x);
            const double k3x = v_ + 0.5 * h * k2v, k3v = accel(x_ + 0.5 * h * k2x, k3x);
            const double k4x = v_ + h * k3v, k4v = accel(x_ + h * k3x, k4x);
            x_ += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
            v_ += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
        }
        return force_N * (x_ - x0);
    }
    void save() { saved_x_ = x_, saved_v_ = v_; }
    void restore() { x_ = saved_x_, v_ = saved_v_; }
    void write(const std::string &path) const { writeState(path, x_, v_); }
    void read(const std::string &path) { readState(path, x_, v_); }
    double x() const { return x_; }
    double v() const { return v_; }

private:
    TwoMassParameters p_;
    double x_, v_ = 0.0;
    double saved_x_ = 0.0, saved_v_ = 0.0;
};

/// Mass 2 and the coupling spring: follows mass 1's motion (cubic Hermite between the window's
/// end states) and returns the window-averaged force on mass 1 and the work it did.
class MassTwoSide {
public:
    explicit MassTwoSide(const TwoMassParameters &p) : p_(p) {}

    struct Result {
        double force_on_mass1_N = 0.0;     ///< [N] averaged over the window
        double impulse_on_mass1_N_s = 0.0; ///< [N s] over the window
        double work_on_mass1_J = 0.0;      ///< [J]
    };

    Result advance(double window_s, double xa, double va, double xb, double vb) {
        const unsigned n = substepsFor(window_s, p_.max_substep_s);
        const double h = window_s / n;
        // Hermite basis on s in [0, 1] for position, and its derivative for velocity.
        auto x1 = [&](double t) {
            const double s = t / window_s, s2 = s * s, s3 = s2 * s;
            return (2 * s3 - 3 * s2 + 1) * xa + (s3 - 2 * s2 + s) * window_s * va +
                   (-2 * s3 + 3 * s2) * xb + (s3 - s2) * window_s * vb;
        };
        auto v1 = [&](double t) {
            const double s = t / window_s, s2 = s * s;
            return ((6 * s2 - 6 * s) * xa + (3 * s2 - 4 * s + 1) * window_s * va +
                    (-6 * s2 + 6 * s) * xb + (3 * s2 - 2 * s) * window_s * vb) /
                   window_s;
        };
        // y = (x2, v2, impulse on mass 1, work on mass 1)
        auto rate = [&](double t, const Eigen::Vector4d &y) {
            const double coupling = p_.kc_N_m * (x1(t) - y[0]) + p_.cc_N_s_m * (v1(t) - y[1]);
            const double a2 = (coupling - p_.k2_N_m * y[0]) / p_.m2_kg;
            return Eigen::Vector4d(y[1], a2, -coupling, -coupling * v1(t));
        };
        Eigen::Vector4d y(x_, v_, 0.0, 0.0);
        for (unsigned i = 0; i < n; ++i) {
            const double t = i * h;
            const Eigen::Vector4d k1 = rate(t, y);
            const Eigen::Vector4d k2 = rate(t + 0.5 * h, y + 0.5 * h * k1);
            const Eigen::Vector4d k3 = rate(t + 0.5 * h, y + 0.5 * h * k2);
            const Eigen::Vector4d k4 = rate(t + h, y + h * k3);
            y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
        }
        x_ = y[0];
        v_ = y[1];
        return Result{y[2] / window_s, y[2], y[3]};
    }
    void save() { saved_x_ = x_, saved_v_ = v_; }
    void restore() { x_ = saved_x_, v_ = saved_v_; }
    void write(const std::string &path) const { writeState(path, x_, v_); }
    void read(const std::string &path) { readState(path, x_, v_); }
    double x() const { return x_; }

private:
    TwoMassParameters p_;
    double x_ = 0.0, v_ = 0.0;
    double saved_x_ = 0.0, saved_v_ = 0.0;
};

} // namespace grainlink::examples
