#include "grainlink/mbs/Mole.hpp"

#include "JointFrames.hpp"

#include "grainlink/dem/TriangleMesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace grainlink::mbs {

namespace {

using SimTK::Pi;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInnerRadius_m = 0.0105; ///< [m] radius of the internal bodies (inertia only)
constexpr double kHammerLength_m = 0.06;  ///< [m] (inertia and layout only)
constexpr double kSuppressorLength_m = 0.12;

/// Hertz contact with Hunt-Crossley dissipation, F = K δ^{3/2} (1 + 3/2 c δ̇), never pulling
/// (docs/physics.md §10.3).
double huntCrossley(double K, double c, double depth, double rate) {
    if (depth <= 0.0)
        return 0.0;
    return std::max(0.0, K * depth * std::sqrt(depth) * (1.0 + 1.5 * c * rate));
}

/// The mechanism's springs, dampers and the two impact contacts as mobility forces on the two
/// slider coordinates: q_s (suppressor from its seat, along +z) and q_h (hammer relative to the
/// suppressor). The hammer's position from the anvil is y_h = q_s + q_h. All forces are internal
/// pairs, so they cannot change the mole's momentum.
class MechanismForce : public SimTK::Force::Custom::Implementation {
public:
    struct Parameters {
        double k_drive, preload_drive_m, c_drive; // drive spring: compression δ0 + q_h
        double k_brake, preload_brake_m, c_brake; // brake spring: compression δb0 + q_s
        double K, c_contact;
    };
    MechanismForce(const SimTK::MobilizedBody::Slider &suppressor,
                   const SimTK::MobilizedBody::Slider &hammer, const Parameters &p)
        : suppressor_(suppressor), hammer_(hammer), p_(p) {}

    void calcForce(const SimTK::State &s, SimTK::Vector_<SimTK::SpatialVec> &,
                   SimTK::Vector_<SimTK::Vec3> &, SimTK::Vector &mobility) const override {
        const double qs = suppressor_.getOneQ(s, SimTK::MobilizerQIndex(0));
        const double qh = hammer_.getOneQ(s, SimTK::MobilizerQIndex(0));
        const double us = suppressor_.getOneU(s, SimTK::MobilizerUIndex(0));
        const double uh = hammer_.getOneU(s, SimTK::MobilizerUIndex(0));
        // Drive spring between hammer and suppressor (pushes them apart), with its damper.
        const double drive = p_.k_drive * std::max(0.0, p_.preload_drive_m + qh) + p_.c_drive * uh;
        // Brake spring between suppressor and hull back, with its damper.
        const double brake = p_.k_brake * std::max(0.0, p_.preload_brake_m + qs) + p_.c_brake * us;
        // Impacts: hammer on the anvil (y_h < 0), suppressor on its seat (q_s < 0).
        const double anvil = huntCrossley(p_.K, p_.c_contact, -(qs + qh), -(us + uh));
        const double seat = huntCrossley(p_.K, p_.c_contact, -qs, -us);
        // Generalized forces by virtual work: a pair acting on y_h loads both q_s and q_h.
        hammer_.applyOneMobilityForce(s, SimTK::MobilizerUIndex(0), -drive + anvil, mobility);
        suppressor_.applyOneMobilityForce(s, SimTK::MobilizerUIndex(0), -brake + anvil + seat,
                                          mobility);
    }

    SimTK::Real calcPotentialEnergy(const SimTK::State &s) const override {
        const double qs = suppressor_.getOneQ(s, SimTK::MobilizerQIndex(0));
        const double qh = hammer_.getOneQ(s, SimTK::MobilizerQIndex(0));
        const double d = std::max(0.0, p_.preload_drive_m + qh);
        const double b = std::max(0.0, p_.preload_brake_m + qs);
        auto hertz = [&](double depth) {
            return depth > 0.0 ? 0.4 * p_.K * depth * depth * std::sqrt(depth) : 0.0;
        };
        return 0.5 * p_.k_drive * d * d + 0.5 * p_.k_brake * b * b + hertz(-(qs + qh)) + hertz(-qs);
    }

private:
    SimTK::MobilizedBody::Slider suppressor_, hammer_;
    Parameters p_;
};

/// The cam's lift of the hammer coordinate (docs/physics.md §10.2): from (q0, u0) when the cam
/// engages to q1 at rest after `duration`, a cycloidal rise plus a blend that starts at the
/// current rate: q(τ) = q0 + u0 T τ (1-τ)² + (q1 - q0)(τ - sin 2πτ / 2π), τ = (t - t0) / T.
class CamLift : public SimTK::Function {
public:
    explicit CamLift(const Mole::Cam *cam) : cam_(cam) {}
    SimTK::Real calcValue(const SimTK::Vector &x) const override { return eval(x[0], 0); }
    SimTK::Real calcDerivative(const SimTK::Array_<int> &components,
                               const SimTK::Vector &x) const override {
        return eval(x[0], static_cast<int>(components.size()));
    }
    int getArgumentSize() const override { return 1; }
    int getMaxDerivativeOrder() const override { return 2; }
    SimTK::Function *clone() const override { return new CamLift(cam_); }

private:
    double eval(double t, int order) const {
        const Mole::Cam &c = *cam_;
        const double T = c.duration_s;
        const double tau = std::clamp((t - c.start_s) / T, 0.0, 1.0);
        const double lift = c.q1_m - c.q0_m;
        const double w = 2.0 * Pi;
        switch (order) {
        case 0:
            return c.q0_m + c.u0_m_s * T * tau * (1 - tau) * (1 - tau) +
                   lift * (tau - std::sin(w * tau) / w);
        case 1:
            return c.u0_m_s * (1 - tau) * (1 - 3 * tau) + lift * (1 - std::cos(w * tau)) / T;
        case 2:
            if (tau >= 1.0)
                return 0.0;
            return c.u0_m_s * (6 * tau - 4) / T + lift * w * std::sin(w * tau) / (T * T);
        default:
            return 0.0;
        }
    }
    const Mole::Cam *cam_;
};

void require(bool ok, const std::string &message) {
    if (!ok)
        throw ModelError("mole: " + message);
}

} // namespace

struct Mole::Gaps {
    double t_s;
    double anvil_m, anvil_rate_m_s, anvil_acc_m_s2; ///< y_h = q_s + q_h and its derivatives
    double seat_m, seat_rate_m_s, seat_acc_m_s2;    ///< q_s and its derivatives
};

MeshShape moleHullMesh(const MoleSettings &s) {
    require(s.mesh_segments >= 3, "mesh_segments must be at least 3");
    require(s.mesh_axial_segments >= 1, "mesh_axial_segments must be at least 1");
    const int n = static_cast<int>(s.mesh_segments);
    const double R = 0.5 * s.hull_diameter_m, L = s.hull_length_m, tip = s.tip_length_m;
    const double cylinder = L - tip;
    // Cone rings about as long as the cylinder's (at least one).
    const int cone_rings =
        std::max(1, static_cast<int>(std::lround(s.mesh_axial_segments * tip / cylinder)));
    MeshShape mesh;
    mesh.vertices_m.push_back(Vec3::Zero()); // apex
    auto ring = [&](double radius, double z) {
        const int first = static_cast<int>(mesh.vertices_m.size());
        for (int i = 0; i < n; ++i) {
            const double a = 2.0 * Pi * i / n;
            mesh.vertices_m.emplace_back(radius * std::cos(a), radius * std::sin(a), z);
        }
        return first;
    };
    // Counter-clockwise seen from outside: around +z, then towards the back.
    auto band = [&](int a, int b) {
        for (int i = 0; i < n; ++i) {
            const int j = (i + 1) % n;
            mesh.triangles.push_back({a + i, a + j, b + j});
            mesh.triangles.push_back({a + i, b + j, b + i});
        }
    };
    int previous = ring(R / cone_rings, tip / cone_rings);
    for (int i = 0; i < n; ++i)
        mesh.triangles.push_back({0, previous + (i + 1) % n, previous + i});
    for (int r = 2; r <= cone_rings; ++r) {
        const int next = ring(R * r / cone_rings, tip * r / cone_rings);
        band(previous, next);
        previous = next;
    }
    for (unsigned r = 1; r <= s.mesh_axial_segments; ++r) {
        const int next = ring(R, tip + cylinder * r / s.mesh_axial_segments);
        band(previous, next);
        previous = next;
    }
    const int back = static_cast<int>(mesh.vertices_m.size());
    mesh.vertices_m.emplace_back(0.0, 0.0, L);
    for (int i = 0; i < n; ++i)
        mesh.triangles.push_back({back, previous + i, previous + (i + 1) % n});
    return mesh;
}

Mole::Mole(const MoleSettings &settings)
    : SimbodyModel(settings.gravity_m_s2, settings.integrator), settings_(settings) {
    const auto &s = settings_;
    require(s.hull_length_m > 0 && s.hull_diameter_m > 0,
            "hull_length_m and hull_diameter_m must be positive");
    require(s.tip_length_m > 0 && s.tip_length_m < s.hull_length_m,
            "tip_length_m must lie in (0, hull_length_m)");
    require(s.hull_mass_kg > 0 && s.hammer_mass_kg > 0 && s.suppressor_mass_kg > 0,
            "hull_mass_kg, hammer_mass_kg and suppressor_mass_kg must be positive");
    require(s.stroke_energy_J > 0 && s.cam_lift_m > 0 && s.drive_spring_preload_m >= 0,
            "need stroke_energy_J > 0, cam_lift_m > 0, drive_spring_preload_m >= 0");
    require(s.drive_damping_N_s_m >= 0 && s.brake_damping_N_s_m >= 0 &&
                s.contact_dissipation_s_m >= 0,
            "damping coefficients must not be negative");
    require(s.contact_stiffness_N_m1_5 > 0, "contact_stiffness_N_m1_5 must be positive");
    require(s.stroke_period_s > 0 && s.cocking_duration_s > 0 &&
                s.cocking_duration_s < s.stroke_period_s,
            "need 0 < cocking_duration_s < stroke_period_s");
    require(s.first_cocking_s >= 0 && s.impact_window_s >= 0,
            "first_cocking_s and impact_window_s must not be negative");
    require(s.impact_max_step_s > 0, "impact_max_step_s must be positive");
    require(s.impact_macro_step_s > 0 && s.cocking_macro_step_s >= s.impact_macro_step_s,
            "need 0 < impact_macro_step_s <= cocking_macro_step_s");
    // Drive spring from the stroke energy, E = k/2 ((δ0 + s)² - δ0²) (physics.md §10.1).
    const double d0 = s.drive_spring_preload_m, lift = s.cam_lift_m;
    drive_stiffness_ = 2.0 * s.stroke_energy_J / (lift * (lift + 2.0 * d0));
    const double drive_preload_N = drive_stiffness_ * d0;
    // At rest the brake spring must hold the suppressor on its seat against the drive preload
    // (the suppressor's weight along the axis helps while the mole stands tip down), and the
    // hammer must rest on the anvil.
    const double g_axis = s.gravity_m_s2.z();
    require(s.brake_spring_preload_N - drive_preload_N - s.suppressor_mass_kg * g_axis > 0,
            "brake_spring_preload_N (" + std::to_string(s.brake_spring_preload_N) +
                " N) must exceed the drive spring's preload (" + std::to_string(drive_preload_N) +
                " N) so the suppressor rests on its seat; raise it or lower "
                "drive_spring_preload_m");
    require(drive_preload_N - s.hammer_mass_kg * g_axis >= 0,
            "the hammer would not rest on the anvil: raise drive_spring_preload_m");
    require(s.brake_spring_stiffness_N_m > 0,
            "brake_spring_stiffness_N_m must be positive (it carries the preload)");
    const double brake_preload_m = s.brake_spring_preload_N / s.brake_spring_stiffness_N_m;

    // Layout along the hull axis (assumed, physics.md §10): anvil just behind the tip, hammer
    // resting on it, suppressor behind the hammer.
    z_anvil_m_ = s.tip_length_m + 0.01;
    z_hammer_m_ = z_anvil_m_ + 0.5 * kHammerLength_m;
    z_suppressor_m_ = z_anvil_m_ + kHammerLength_m + lift + 0.02 + 0.5 * kSuppressorLength_m;
    require(z_suppressor_m_ + 0.5 * kSuppressorLength_m < s.hull_length_m,
            "the hull is too short for the hammer mechanism (needs more than " +
                std::to_string(z_suppressor_m_ + 0.5 * kSuppressorLength_m) + " m)");

    const double R = 0.5 * s.hull_diameter_m, L = s.hull_length_m;
    // Hull: a thin-walled tube of uniform mass (assumed), centre of mass at mid-length.
    const Vec3 hull_inertia(s.hull_mass_kg * (R * R / 2 + L * L / 12),
                            s.hull_mass_kg * (R * R / 2 + L * L / 12), s.hull_mass_kg * R * R);
    const Vec3 hull_com(0, 0, 0.5 * L);
    const SimTK::Body::Rigid hull_body(
        SimTK::MassProperties(s.hull_mass_kg, toSimTK(hull_com),
                              SimTK::Inertia(toSimTK(hull_inertia))
                                  .shiftFromMassCenter(-toSimTK(hull_com), s.hull_mass_kg)));
    if (s.hull_fixed)
        hull_ = SimTK::MobilizedBody::Weld(matter_.Ground(),
                                           SimTK::Transform(toSimTK(s.start_tip_position_m)),
                                           hull_body, SimTK::Transform());
    else
        hull_ = SimTK::MobilizedBody::Free(matter_.Ground(), SimTK::Transform(), hull_body,
                                           SimTK::Transform());
    // Solid cylinders of the inner radius (assumed) for the internal bodies' inertia.
    auto cylinder = [](double m, double length) {
        const double r = kInnerRadius_m;
        const double transverse = m * (3 * r * r + length * length) / 12;
        return SimTK::Body::Rigid(SimTK::MassProperties(
            m, SimTK::Vec3(0), SimTK::Inertia(transverse, transverse, 0.5 * m * r * r)));
    };
    suppressor_ = SimTK::MobilizedBody::Slider(
        hull_, SimTK::Transform(kXToZ, SimTK::Vec3(0, 0, z_suppressor_m_)),
        cylinder(s.suppressor_mass_kg, kSuppressorLength_m), SimTK::Transform(kXToZ));
    hammer_ = SimTK::MobilizedBody::Slider(
        suppressor_, SimTK::Transform(kXToZ, SimTK::Vec3(0, 0, z_hammer_m_ - z_suppressor_m_)),
        cylinder(s.hammer_mass_kg, kHammerLength_m), SimTK::Transform(kXToZ));

    MechanismForce::Parameters p{drive_stiffness_,
                                 d0,
                                 s.drive_damping_N_s_m,
                                 s.brake_spring_stiffness_N_m,
                                 brake_preload_m,
                                 s.brake_damping_N_s_m,
                                 s.contact_stiffness_N_m1_5,
                                 s.contact_dissipation_s_m};
    SimTK::Force::Custom(forces_, new MechanismForce(suppressor_, hammer_, p));
    cam_constraint_ = SimTK::Constraint::PrescribedMotion(matter_, new CamLift(&controller_.cam),
                                                          hammer_.getMobilizedBodyIndex(),
                                                          SimTK::MobilizerQIndex(0));
    cam_constraint_.setDisabledByDefault(true);

    BodyDescription hull;
    hull.name = s.hull_name;
    hull.mass.mass_kg = s.hull_mass_kg;
    hull.mass.center_of_mass_m = hull_com;
    hull.mass.inertia_diagonal_kg_m2 = hull_inertia;
    hull.geometry = moleHullMesh(s);
    addCoupled(hull, hull_);
    finishBuilding();

    if (!s.hull_fixed)
        hull_.setQToFitTranslation(state(), toSimTK(s.start_tip_position_m));
    setStaticRest();
    controller_.impacts = {kNaN, kNaN, kNaN, kNaN};
    SimbodyModel::saveState();
    saved_controller_ = controller_;
}

void Mole::setStaticRest() {
    // Hammer on the anvil and suppressor on its seat, each pressed by its Hertz contact just
    // enough to balance the springs and the weights along the axis (mole vertical): no start-up
    // transient from a misplaced rest.
    const auto &s = settings_;
    const double k = drive_stiffness_, K = s.contact_stiffness_N_m1_5;
    const double g = s.gravity_m_s2.z(); // along the hull axis at the vertical start
    double qs = 0.0, qh = 0.0;
    for (int iteration = 0; iteration < 20; ++iteration) {
        const double drive = k * (s.drive_spring_preload_m + qh);
        const double brake = s.brake_spring_preload_N + s.brake_spring_stiffness_N_m * qs;
        const double anvil = drive - s.hammer_mass_kg * g;
        const double seat = brake - drive - s.suppressor_mass_kg * g;
        const double ys = -std::cbrt((anvil / K) * (anvil / K)); // δ = (F/K)^{2/3}
        qs = -std::cbrt((seat / K) * (seat / K));
        qh = ys - qs;
    }
    SimTK::State &st = state();
    suppressor_.setOneQ(st, SimTK::MobilizerQIndex(0), qs);
    hammer_.setOneQ(st, SimTK::MobilizerQIndex(0), qh);
    system_.realize(st, SimTK::Stage::Velocity);
}

double Mole::cockingStart(long k) const {
    return settings_.first_cocking_s + static_cast<double>(k) * settings_.stroke_period_s;
}

double Mole::releaseTime(long k) const {
    return cockingStart(k) + settings_.cocking_duration_s;
}

void Mole::applyWrenches(const std::vector<Wrench> &wrenches) {
    SimbodyModel::applyWrenches(wrenches);
    applied_ = wrenches.front();
}

void Mole::saveState() {
    SimbodyModel::saveState();
    saved_controller_ = controller_;
    saved_applied_ = applied_;
}

void Mole::restoreState() {
    SimbodyModel::restoreState();
    controller_ = saved_controller_;
    applied_ = saved_applied_;
}

void Mole::handleEvents() {
    // Event times are compared with a tolerance far below any step the integrator takes.
    constexpr double eps = 1e-12;
    SimTK::State &st = state();
    auto &c = controller_;
    for (;;) {
        const double t = st.getTime();
        if (!c.cam_engaged && t >= cockingStart(c.next_stroke) - eps) {
            // The cam engages the hammer where it is, at its current rate (no impulse).
            c.cam.start_s = cockingStart(c.next_stroke);
            c.cam.duration_s = settings_.cocking_duration_s;
            c.cam.q0_m = hammer_.getOneQ(st, SimTK::MobilizerQIndex(0));
            c.cam.u0_m_s = hammer_.getOneU(st, SimTK::MobilizerUIndex(0));
            c.cam.q1_m = settings_.cam_lift_m;
            c.cam_engaged = true;
            cam_constraint_.enable(st);
        } else if (c.cam_engaged && t >= releaseTime(c.next_stroke) - eps) {
            cam_constraint_.disable(st);
            c.cam_engaged = false;
            c.last_release_s = releaseTime(c.next_stroke);
            ++c.next_stroke;
            ++c.strokes;
            c.primary_seen = c.secondary_seen = false;
            c.impacts = {kNaN, kNaN, kNaN, kNaN};
        } else {
            break;
        }
    }
    system_.realize(st, SimTK::Stage::Velocity);
}

std::vector<double> Mole::advanceTo(double time_s) {
    double work = 0.0;
    handleEvents();
    while (state().getTime() < time_s) {
        const double next_event = controller_.cam_engaged ? releaseTime(controller_.next_stroke)
                                                          : cockingStart(controller_.next_stroke);
        work += integrateTo(std::min(time_s, next_event));
        handleEvents();
    }
    return {work};
}

Mole::Gaps Mole::gaps(const SimTK::State &s) const {
    system_.realize(s, SimTK::Stage::Acceleration);
    const SimTK::MobilizerQIndex q(0);
    const SimTK::MobilizerUIndex u(0);
    const double qs = suppressor_.getOneQ(s, q), qh = hammer_.getOneQ(s, q);
    const double us = suppressor_.getOneU(s, u), uh = hammer_.getOneU(s, u);
    const double as = suppressor_.getOneUDot(s, u), ah = hammer_.getOneUDot(s, u);
    return {s.getTime(), qs + qh, us + uh, as + ah, qs, us, as};
}

void Mole::detectImpacts(const Gaps &before, const Gaps &after) {
    // First touch between two steps (at most impact_max_step_s apart): time and closing speed
    // at zero gap from the state before it, at constant acceleration over the remaining gap
    // (physics.md §10.4): g - v τ - a τ²/2 = 0, v_touch = sqrt(v² + 2 a g).
    struct Touch {
        double time_s, speed_m_s;
    };
    auto touch = [&](double gap, double rate, double acc) {
        const double v = -rate, a = -acc; // closing speed and acceleration
        const double speed = std::sqrt(std::max(0.0, v * v + 2.0 * a * gap));
        const double tau = v + speed > 0.0 ? 2.0 * gap / (v + speed) : after.t_s - before.t_s;
        return Touch{before.t_s + std::min(tau, after.t_s - before.t_s), speed};
    };
    auto &c = controller_;
    if (!c.primary_seen && before.anvil_m > 0.0 && after.anvil_m <= 0.0) {
        const Touch t = touch(before.anvil_m, before.anvil_rate_m_s, before.anvil_acc_m_s2);
        c.primary_seen = true;
        c.impacts.primary_time_s = t.time_s;
        c.impacts.primary_speed_m_s = t.speed_m_s;
    }
    if (!c.secondary_seen && before.seat_m > 0.0 && after.seat_m <= 0.0) {
        const Touch t = touch(before.seat_m, before.seat_rate_m_s, before.seat_acc_m_s2);
        c.secondary_seen = true;
        c.impacts.secondary_time_s = t.time_s;
        c.impacts.secondary_speed_m_s = t.speed_m_s;
    }
}

double Mole::integrateTo(double time_s) {
    if (time_s <= state().getTime())
        return 0.0;
    // Until both impacts of a stroke are seen, short steps: the touch is found within one.
    const bool watch =
        !controller_.cam_engaged && (!controller_.primary_seen || !controller_.secondary_seen);
    SimTK::RungeKuttaMersonIntegrator integrator(system_);
    integrator.setAccuracy(settings_.integrator.accuracy);
    integrator.setMaximumStepSize(
        watch ? std::min(settings_.impact_max_step_s, settings_.integrator.max_step_s)
              : settings_.integrator.max_step_s);
    integrator.setReturnEveryInternalStep(true);
    integrator.setFinalTime(time_s);
    integrator.initialize(state());
    // Work of the soil's constant wrench on the hull: ∫ F·v + T·ω dt, trapezoid rule per step.
    auto power = [&](const SimTK::State &s) {
        const Vec3 v = fromSimTK(hull_.getBodyOriginVelocity(s));
        const Vec3 w = fromSimTK(hull_.getBodyAngularVelocity(s));
        return applied_.force_N.dot(v) + applied_.torque_N_m.dot(w);
    };
    double work = 0.0;
    double t_previous = integrator.getTime();
    double p_previous = power(integrator.getState());
    Gaps g_previous{};
    if (watch)
        g_previous = gaps(integrator.getState());
    while (integrator.getTime() < time_s) {
        const auto status = integrator.stepTo(time_s);
        if (status == SimTK::Integrator::EndOfSimulation || integrator.isSimulationOver())
            if (integrator.getTerminationReason() != SimTK::Integrator::ReachedFinalTime)
                throw ModelError("mole: Simbody integration stopped at t = " +
                                 std::to_string(integrator.getTime()) + " s: " +
                                 SimTK::Integrator::getTerminationReasonString(
                                     integrator.getTerminationReason()));
        const SimTK::State &s = integrator.getState();
        const double t = integrator.getTime();
        system_.realize(s, SimTK::Stage::Velocity);
        const double p = power(s);
        work += 0.5 * (p + p_previous) * (t - t_previous);
        p_previous = p;
        t_previous = t;
        if (watch) {
            const Gaps g = gaps(s);
            detectImpacts(g_previous, g);
            g_previous = g;
        }
    }
    state() = integrator.getState();
    return work;
}

Mole::Phase Mole::phase() const {
    if (controller_.cam_engaged)
        return Phase::Cocking;
    if (state().getTime() < controller_.last_release_s + settings_.impact_window_s)
        return Phase::Released;
    return Phase::Resting;
}

double Mole::suggestedMacroStep_s() const {
    if (phase() == Phase::Released)
        return settings_.impact_macro_step_s;
    const double next_release = releaseTime(controller_.next_stroke);
    const double to_release = next_release - state().getTime();
    return std::max(settings_.impact_macro_step_s,
                    std::min(settings_.cocking_macro_step_s, to_release));
}

double Mole::hammerPosition_m() const {
    return suppressor_.getOneQ(state(), SimTK::MobilizerQIndex(0)) +
           hammer_.getOneQ(state(), SimTK::MobilizerQIndex(0));
}

double Mole::suppressorPosition_m() const {
    return suppressor_.getOneQ(state(), SimTK::MobilizerQIndex(0));
}

double Mole::hammerVelocity_m_s() const {
    return suppressor_.getOneU(state(), SimTK::MobilizerUIndex(0)) +
           hammer_.getOneU(state(), SimTK::MobilizerUIndex(0));
}

double Mole::suppressorVelocity_m_s() const {
    return suppressor_.getOneU(state(), SimTK::MobilizerUIndex(0));
}

double Mole::driveSpringEnergy_J() const {
    const double d = std::max(0.0, settings_.drive_spring_preload_m +
                                       hammer_.getOneQ(state(), SimTK::MobilizerQIndex(0)));
    return 0.5 * drive_stiffness_ * d * d;
}

Vec3 Mole::totalMomentum_kg_m_s() const {
    system_.realize(state(), SimTK::Stage::Velocity);
    return matter_.calcSystemMass(state()) *
           fromSimTK(matter_.calcSystemMassCenterVelocityInGround(state()));
}

double Mole::mechanicalEnergy_J() const {
    system_.realize(state(), SimTK::Stage::Dynamics);
    return system_.calcEnergy(state());
}

std::map<std::string, double> Mole::observables() const {
    const SimTK::State &st = state();
    system_.realize(st, SimTK::Stage::Acceleration);
    std::map<std::string, double> o;
    const Vec3 tip = fromSimTK(hull_.getBodyOriginLocation(st));
    const Vec3 v = fromSimTK(hull_.getBodyOriginVelocity(st));
    const Vec3 axis = fromSimTK(hull_.getBodyRotation(st).z());
    o["tip_x_m"] = tip.x();
    o["tip_y_m"] = tip.y();
    o["tip_z_m"] = tip.z();
    o["penetration_m"] = settings_.start_tip_position_m.z() - tip.z();
    o["hull_vz_m_s"] = v.z();
    o["hull_speed_m_s"] = v.norm();
    o["hull_tilt_deg"] = std::acos(std::clamp(axis.z(), -1.0, 1.0)) * 180.0 / Pi;
    o["stroke_count"] = controller_.strokes;
    o["phase"] = static_cast<double>(static_cast<int>(phase())); // 0 cocking 1 released 2 resting
    o["cam_engaged"] = controller_.cam_engaged ? 1.0 : 0.0;
    o["hammer_position_m"] = hammerPosition_m();
    o["suppressor_position_m"] = suppressorPosition_m();
    o["hammer_velocity_m_s"] = hammerVelocity_m_s();
    o["suppressor_velocity_m_s"] = suppressorVelocity_m_s();
    o["drive_spring_energy_J"] = driveSpringEnergy_J();
    // The cam's force on the hammer along +z (drawing it back); minus the Lagrange multiplier.
    o["cam_force_N"] =
        controller_.cam_engaged ? -cam_constraint_.getMultipliersAsVector(st)[0] : 0.0;
    o["primary_impact_time_s"] = controller_.impacts.primary_time_s;
    o["primary_impact_speed_m_s"] = controller_.impacts.primary_speed_m_s;
    o["secondary_impact_time_s"] = controller_.impacts.secondary_time_s;
    o["secondary_impact_speed_m_s"] = controller_.impacts.secondary_speed_m_s;
    o["suggested_macro_step_s"] = suggestedMacroStep_s();
    return o;
}

std::string Mole::checkpointExtras() const {
    const auto &c = controller_;
    std::ostringstream os;
    os.precision(17);
    os << "mole " << (c.cam_engaged ? 1 : 0) << ' ' << c.next_stroke << ' ' << c.strokes << ' '
       << c.last_release_s << ' ' << (c.primary_seen ? 1 : 0) << ' ' << (c.secondary_seen ? 1 : 0)
       << ' ' << c.impacts.primary_time_s << ' ' << c.impacts.primary_speed_m_s << ' '
       << c.impacts.secondary_time_s << ' ' << c.impacts.secondary_speed_m_s << ' ' << c.cam.start_s
       << ' ' << c.cam.q0_m << ' ' << c.cam.u0_m_s << ' ' << c.cam.q1_m << ' ' << c.cam.duration_s;
    return os.str();
}

void Mole::readCheckpointExtras(const std::string &line) {
    std::istringstream in(line);
    std::string tag;
    Controller c;
    int engaged = 0, primary = 0, secondary = 0;
    // NaN is written as "nan", which operator>> does not read: parse every number by strtod.
    std::vector<double> x;
    in >> tag >> engaged >> c.next_stroke >> c.strokes;
    std::string word;
    while (in >> word)
        x.push_back(std::strtod(word.c_str(), nullptr));
    if (tag != "mole" || x.size() != 12)
        throw ModelError("mole checkpoint: expected the mole's controller line, got '" + line +
                         "'");
    c.cam_engaged = engaged != 0;
    c.last_release_s = x[0];
    primary = static_cast<int>(x[1]);
    secondary = static_cast<int>(x[2]);
    c.primary_seen = primary != 0;
    c.secondary_seen = secondary != 0;
    c.impacts = {x[3], x[4], x[5], x[6]};
    c.cam = {x[7], x[8], x[9], x[10], x[11]};
    controller_ = c;
    SimTK::State &st = state();
    if (c.cam_engaged)
        cam_constraint_.enable(st);
    else
        cam_constraint_.disable(st);
    system_.realize(st, SimTK::Stage::Velocity);
}

MoleSettings parseMole(const config::ConfigNode &node) {
    MoleSettings s;
    // Optional keys: a positive number where the model needs one, else a plain number.
    auto positive = [&](const char *key, double &value) {
        if (auto n = node.optional(key))
            value = n->positive();
    };
    auto number = [&](const char *key, double &value) { value = node.number(key, value); };
    auto count = [&](const char *key, unsigned &value, long long least) {
        value = static_cast<unsigned>(node.integer(key, least, dem::kMaxMeshSegments, value));
    };
    s.hull_name = node.text("hull_name", s.hull_name);
    positive("hull_length_m", s.hull_length_m);
    positive("hull_diameter_m", s.hull_diameter_m);
    positive("tip_length_m", s.tip_length_m);
    count("mesh_segments", s.mesh_segments, 3);
    count("mesh_axial_segments", s.mesh_axial_segments, 1);
    positive("hull_mass_kg", s.hull_mass_kg);
    positive("hammer_mass_kg", s.hammer_mass_kg);
    positive("suppressor_mass_kg", s.suppressor_mass_kg);
    positive("stroke_energy_J", s.stroke_energy_J);
    positive("cam_lift_m", s.cam_lift_m);
    number("drive_spring_preload_m", s.drive_spring_preload_m);
    positive("brake_spring_stiffness_N_m", s.brake_spring_stiffness_N_m);
    number("brake_spring_preload_N", s.brake_spring_preload_N);
    number("drive_damping_N_s_m", s.drive_damping_N_s_m);
    number("brake_damping_N_s_m", s.brake_damping_N_s_m);
    positive("contact_stiffness_N_m1_5", s.contact_stiffness_N_m1_5);
    number("contact_dissipation_s_m", s.contact_dissipation_s_m);
    positive("stroke_period_s", s.stroke_period_s);
    positive("cocking_duration_s", s.cocking_duration_s);
    number("first_cocking_s", s.first_cocking_s);
    number("impact_window_s", s.impact_window_s);
    positive("impact_max_step_s", s.impact_max_step_s);
    positive("impact_macro_step_s", s.impact_macro_step_s);
    positive("cocking_macro_step_s", s.cocking_macro_step_s);
    s.hull_fixed = node.boolean("hull_fixed", s.hull_fixed);
    s.start_tip_position_m = node["start_tip_position_m"].vec3();
    if (auto g = node.optional("gravity_m_s2"))
        s.gravity_m_s2 = g->vec3();
    node.finish();
    // Relations between keys are checked by the model, which names the keys.
    return s;
}

std::vector<MoleStroke> moleStrokes(const std::vector<double> &time_s,
                                    const std::vector<double> &stroke_count,
                                    const std::vector<double> &penetration_m,
                                    const std::vector<double> &hull_force_z_N) {
    const std::size_t n = time_s.size();
    if (stroke_count.size() != n || penetration_m.size() != n || hull_force_z_N.size() != n)
        throw ModelError("moleStrokes: the series have different lengths");
    std::vector<MoleStroke> strokes;
    std::vector<double> start_s;       // each stroke's first window's start
    double previous_penetration = 0.0; // at the end of the previous stroke, or before the first
    for (std::size_t i = 0; i < n; ++i) {
        const int k = int(std::lround(stroke_count[i]));
        // The window's force acts from the previous window's end to this one's.
        const double window_start = i > 0 ? time_s[i - 1] : 0.0;
        if (k == 0) {
            previous_penetration = penetration_m[i];
            continue;
        }
        if (strokes.empty() || strokes.back().stroke != k) {
            if (!strokes.empty())
                previous_penetration = strokes.back().penetration_m;
            strokes.push_back({k, 0.0, 0.0, 0.0, hull_force_z_N[i], 0.0, 0.0});
            start_s.push_back(window_start);
        }
        MoleStroke &s = strokes.back();
        s.end_time_s = time_s[i];
        s.penetration_m = penetration_m[i];
        s.advance_m = penetration_m[i] - previous_penetration;
        s.peak_hull_force_N = std::max(s.peak_hull_force_N, hull_force_z_N[i]);
        s.hull_impulse_N_s += hull_force_z_N[i] * (time_s[i] - window_start);
    }
    for (std::size_t j = 0; j < strokes.size(); ++j) {
        const double span = strokes[j].end_time_s - start_s[j];
        strokes[j].mean_hull_force_N = span > 0.0 ? strokes[j].hull_impulse_N_s / span : 0.0;
    }
    return strokes;
}

} // namespace grainlink::mbs
