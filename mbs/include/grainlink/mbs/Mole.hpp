#pragma once
// The HP3 "mole" of NASA's InSight mission (DIGEST §6; docs/physics.md §10): a slender hull with
// a conical tip that hammers itself into the soil. Inside, in Simbody: the hull (housing), a
// suppressor mass on a slider along the hull axis, and a hammer on a slider on the suppressor
// (its coordinate is the hammer-suppressor separation the cam works on). A motor-driven cam
// draws the hammer back against the drive (force) spring, then releases it: the hammer strikes
// the anvil in the hull (primary impact), the spring's recoil throws the suppressor back against
// the brake spring, which stops it and returns it onto its seat in the hull (secondary impact).
// Only the hull couples to the soil. Hull frame: origin at the tip apex, axis +z towards the back
// cap; the mole starts vertical, tip down.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/SimbodyModel.hpp"

namespace grainlink::mbs {

struct MoleSettings {
    std::string hull_name = "mole";
    // Hull geometry (docs/physics.md §10 gives the source of every default).
    double hull_length_m = 0.40;      ///< [m] tip apex to back cap
    double hull_diameter_m = 0.027;   ///< [m]
    double tip_length_m = 0.04;       ///< [m] axial length of the conical tip
    unsigned mesh_segments = 24;      ///< facets around the axis
    unsigned mesh_axial_segments = 8; ///< rings along the cylinder
    // Masses.
    double hull_mass_kg = 0.40;       ///< [kg] housing, tip and payload
    double hammer_mass_kg = 0.10;     ///< [kg]
    double suppressor_mass_kg = 0.35; ///< [kg] suppressor with motor, gearbox and cam
    // Stroke.
    double stroke_energy_J = 0.7;             ///< [J] drive-spring energy released per stroke
    double cam_lift_m = 0.007;                ///< [m] how far the cam draws the hammer back
    double drive_spring_preload_m = 0.001;    ///< [m] drive-spring compression at rest
    double brake_spring_stiffness_N_m = 2000; ///< [N/m]
    double brake_spring_preload_N = 30.0;     ///< [N] holds the suppressor on its seat
    double drive_damping_N_s_m = 2.0;         ///< [N s/m] hammer guide and spring losses
    double brake_damping_N_s_m = 10.0;        ///< [N s/m] suppressor guide and spring losses
    double contact_stiffness_N_m1_5 = 1e9;    ///< [N/m^1.5] Hertz K of anvil and seat
    double contact_dissipation_s_m = 0.15;    ///< [s/m] Hunt-Crossley c: e ≈ 1 - c v
    // Timing.
    double stroke_period_s = 3.6;       ///< [s] one stroke per period
    double cocking_duration_s = 3.0;    ///< [s] the cam's lift, then the release
    double first_cocking_s = 0.0;       ///< [s] when the first cocking starts
    double impact_window_s = 0.1;       ///< [s] after a release: "released" phase, small steps
    double impact_max_step_s = 1e-5;    ///< [s] integrator step cap until both impacts are seen
    double impact_macro_step_s = 5e-5;  ///< [s] suggested coupling step around the impacts
    double cocking_macro_step_s = 1e-3; ///< [s] suggested coupling step otherwise
    // Placement and environment.
    bool hull_fixed = false;                  ///< weld the hull to Ground (mechanism bench)
    Vec3 start_tip_position_m = Vec3::Zero(); ///< [m] tip apex at t = 0 (hull vertical)
    Vec3 gravity_m_s2 = Vec3(0, 0, -3.71);    ///< [m/s^2] Mars
    IntegratorSettings integrator;
};

/// The hull's closed surface in the hull frame: cone tip (apex at the origin), cylinder, flat
/// back cap; outward normals.
MeshShape moleHullMesh(const MoleSettings &settings);

/// The impacts of the latest stroke (times are NaN until detected).
struct MoleImpacts {
    double primary_time_s;      ///< [s] hammer on anvil
    double primary_speed_m_s;   ///< [m/s] closing speed at first touch
    double secondary_time_s;    ///< [s] suppressor back on its seat
    double secondary_speed_m_s; ///< [m/s]
};

/// One stroke of a mole run: from its release to the next release (or the run's end).
struct MoleStroke {
    int stroke = 0;                 ///< 1, 2, ...
    double end_time_s = 0.0;        ///< [s] the stroke's last window
    double penetration_m = 0.0;     ///< [m] tip below its start at the stroke's end
    double advance_m = 0.0;         ///< [m] penetration gained in this stroke
    double peak_hull_force_N = 0.0; ///< [N] the soil's largest upward force on the hull
    double hull_impulse_N_s = 0.0;  ///< [N s] the soil's upward impulse on the hull
    double mean_hull_force_N = 0.0; ///< [N] that impulse over the stroke's span
};

/// The strokes of a coupled run from its windows (mbs.csv): each window's end time, the stroke
/// count and penetration at its end, and the soil's vertical force on the hull over it. Stroke k
/// spans the windows from the one where the count becomes k to the last before it becomes k + 1;
/// windows before the first release belong to no stroke.
std::vector<MoleStroke> moleStrokes(const std::vector<double> &time_s,
                                    const std::vector<double> &stroke_count,
                                    const std::vector<double> &penetration_m,
                                    const std::vector<double> &hull_force_z_N);

class Mole final : public SimbodyModel {
public:
    enum class Phase { Cocking, Released, Resting };

    explicit Mole(const MoleSettings &settings);
    Mole(const Mole &) = delete;
    Mole &operator=(const Mole &) = delete;

    void applyWrenches(const std::vector<Wrench> &wrenches) override;
    /// Integrates to `time_s`, stopping at every cocking start and release.
    std::vector<double> advanceTo(double time_s) override;
    std::map<std::string, double> observables() const override;
    void saveState() override;
    void restoreState() override;

    /// The coupling step this model asks for now: small in the impact window after a release,
    /// larger while cocking or resting, but never past the next release.
    double suggestedMacroStep_s() const override;

    Phase phase() const;
    int strokeCount() const { return controller_.strokes; }
    const MoleImpacts &lastImpacts() const { return controller_.impacts; }
    const MoleSettings &settings() const { return settings_; }
    /// Drive-spring stiffness from the stroke energy: E = k/2 ((δ0 + s)² - δ0²).
    double driveSpringStiffness_N_m() const { return drive_stiffness_; }
    /// Hammer and suppressor positions along the hull axis relative to their seats [m].
    double hammerPosition_m() const;
    double suppressorPosition_m() const;
    double hammerVelocity_m_s() const; ///< [m/s] along the hull axis, relative to the hull
    double suppressorVelocity_m_s() const;
    double driveSpringEnergy_J() const;
    /// Diagnostics for the conservation tests: the whole mole's linear momentum (world) and its
    /// mechanical energy (kinetic + springs + contacts + gravity).
    Vec3 totalMomentum_kg_m_s() const;
    double mechanicalEnergy_J() const;

    /// The cam's state: when the current lift started and from where (not part of the State).
    struct Cam {
        double start_s = 0.0;    ///< [s]
        double q0_m = 0.0;       ///< [m] hammer coordinate when the cam engaged
        double u0_m_s = 0.0;     ///< [m/s] its rate then (the lift starts smoothly from it)
        double q1_m = 0.0;       ///< [m] cocked coordinate
        double duration_s = 1.0; ///< [s]
    };

protected:
    std::string checkpointExtras() const override;
    void readCheckpointExtras(const std::string &line) override;

private:
    struct Controller {
        bool cam_engaged = false;
        long next_stroke = 0; ///< index of the next cocking or, while engaged, the current one
        int strokes = 0;      ///< releases so far
        double last_release_s = -1e300;
        bool primary_seen = true, secondary_seen = true;
        MoleImpacts impacts;
        Cam cam;
    };
    struct Gaps;

    double cockingStart(long k) const;
    double releaseTime(long k) const;
    void handleEvents();
    double integrateTo(double time_s);
    Gaps gaps(const SimTK::State &s) const;
    void detectImpacts(const Gaps &before, const Gaps &after);
    void setStaticRest();

    MoleSettings settings_;
    double drive_stiffness_ = 0.0;
    double z_anvil_m_ = 0.0, z_hammer_m_ = 0.0, z_suppressor_m_ = 0.0; ///< [m] rest layout
    SimTK::MobilizedBody hull_;
    SimTK::MobilizedBody::Slider suppressor_, hammer_;
    SimTK::Constraint::PrescribedMotion cam_constraint_;
    Controller controller_, saved_controller_;
    Wrench applied_;
    Wrench saved_applied_;
};

/// Reads a `mole:` section (docs/scenario.md); strict, errors name the key and the line.
MoleSettings parseMole(const config::ConfigNode &node);

} // namespace grainlink::mbs
