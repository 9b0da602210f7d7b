// Models from URDF + YAML (mbs/UrdfModel.cpp): the single-wheel rig read from files against the
// built-in one, joint springs and a compound pendulum against analytic motion, a floating root
// with an STL mesh, and the errors a user sees for malformed files (tolerances stated per check).
#include "grainlink/mbs/UrdfModel.hpp"
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/SingleWheelRig.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace grainlink::mbs;
using grainlink::config::ConfigError;

namespace {

const std::string kData = GRAINLINK_MBS_TEST_DATA;
const std::string kModels = GRAINLINK_MODELS_DIR;

/// The built-in rig with the settings of scenarios/models/single_wheel_rig.{urdf,yaml}.
SingleWheelRigSettings builtInRig() {
    SingleWheelRigSettings s;
    s.wheel.diameter_m = 0.25;
    s.wheel.width_m = 0.1;
    s.wheel_mass_kg = 2.0;
    s.normal_load_kg = 8.33;
    s.horizontal_mass_kg = 8.33;
    s.start_position_m = Vec3(0.1, 0.05, 0.5);
    s.angular_velocity_rad_s = 3.0;
    return s;
}

/// Largest difference between two body states: positions [m], rotation angle [rad], linear
/// [m/s] and angular [rad/s] velocities, each reported separately.
struct StateDiff {
    double position = 0, angle = 0, velocity = 0, angular_velocity = 0;
    void add(const RigidState &a, const RigidState &b) {
        position = std::max(position, (a.position_m - b.position_m).norm());
        angle = std::max(angle, a.orientation.angularDistance(b.orientation));
        velocity = std::max(velocity, (a.linear_velocity_m_s - b.linear_velocity_m_s).norm());
        angular_velocity = std::max(angular_velocity,
                                    (a.angular_velocity_rad_s - b.angular_velocity_rad_s).norm());
    }
};

/// The error message of `f`, which must throw E.
template <class E, class F> std::string messageOf(F &&f) {
    try {
        f();
    } catch (const E &e) {
        return e.what();
    }
    FAIL("expected an exception");
    return "";
}

} // namespace

TEST_CASE("URDF rig moves like the built-in single-wheel rig", "[mbs][urdf]") {
    // Both are Ground -> slider x -> slider z -> pin about y with the same masses, integrated by
    // the same error-controlled Runge-Kutta-Merson (accuracy 1e-8). Only the mobilizer frames
    // differ (any rotation taking the slider's x onto z will do), so the two runs differ by
    // round-off in the same equations (measured: below 1e-15): states must agree to 1e-12 (m,
    // rad, m/s, rad/s, N m), far below the integrator's own error (1e-8 relative), which a
    // wrong mass, inertia, frame or drive would exceed by orders of magnitude.
    const double tolerance = 1e-12;
    const UrdfModelSettings settings = parseUrdfModel(kModels + "/single_wheel_rig.yaml");
    StateDiff diff;
    double torque_diff = 0.0;

    auto compare = [&](SingleWheelRig &rig, UrdfModel &urdf, double from_s, double to_s) {
        for (double t = from_s + 1e-3; t <= to_s + 1e-12; t += 1e-3) {
            rig.advanceTo(t);
            urdf.advanceTo(t);
            diff.add(rig.bodyStates()[0], urdf.bodyStates()[0]);
            const auto o_rig = rig.observables(), o_urdf = urdf.observables();
            torque_diff = std::max(torque_diff, std::abs(o_rig.at("motor_torque_N_m") -
                                                         o_urdf.at("wheel_drive_torque_N_m")));
            CHECK(o_urdf.at("carriage_x_position_m") ==
                  Approx(o_rig.at("carriage_x_m")).margin(tolerance));
            CHECK(o_urdf.at("carriage_z_speed_m_s") ==
                  Approx(o_rig.at("carriage_vz_m_s")).margin(tolerance));
        }
    };

    SECTION("locked free fall, then soil forces with the wheel speed-driven") {
        auto rig_settings = builtInRig();
        rig_settings.rotation_locked = true;
        SingleWheelRig rig(rig_settings);
        UrdfModel urdf(settings);
        urdf.setDrive("wheel", {JointDrive::Mode::Locked, 0.0});

        const auto rb = rig.coupledBodies()[0], ub = urdf.coupledBodies()[0];
        CHECK(ub.name == "wheel");
        CHECK(ub.mass.mass_kg == rb.mass.mass_kg);
        CHECK((ub.mass.inertia_diagonal_kg_m2 - rb.mass.inertia_diagonal_kg_m2).norm() < 1e-15);
        CHECK(std::get<WheelShape>(ub.geometry).diameter_m ==
              std::get<WheelShape>(rb.geometry).diameter_m);
        diff.add(rig.bodyStates()[0], urdf.bodyStates()[0]);

        rig.applyWrenches({Wrench{}});
        urdf.applyWrenches({Wrench{}});
        compare(rig, urdf, 0.0, 0.2); // free fall, rotation locked
        Wrench soil;
        soil.force_N = Vec3(-5.0, 1.0, 60.0); // y is carried by the rig's guides
        soil.torque_N_m = Vec3(0.3, -2.0, 0.1);
        rig.applyWrenches({soil});
        urdf.applyWrenches({soil});
        rig.setRotationLocked(false);
        urdf.setDrive("wheel", {JointDrive::Mode::Speed, 3.0});
        compare(rig, urdf, 0.2, 0.5);
        // The motion really happened: 0.2 s free fall then 0.3 s at a = (60 - 81.7) / 8.33.
        CHECK(urdf.bodyStates()[0].position_m.z() < 0.5 - 0.19);
        CHECK(urdf.observables().at("wheel_drive_torque_N_m") == Approx(2.0).margin(1e-9));
    }
    SECTION("torque drive: the wheel's inertia and the drawbar force") {
        auto rig_settings = builtInRig();
        rig_settings.drive_torque_N_m = 1.5;
        rig_settings.drawbar_force_N = 4.0;
        SingleWheelRig rig(rig_settings); // the wheel starts at rest under a torque drive
        // The same change a user makes in the YAML: drive: {mode: effort, torque_N_m: 1.5}
        // on the wheel, and the drawbar F_R as an effort drive on the horizontal slider.
        UrdfModelSettings torque_settings = settings;
        for (auto &j : torque_settings.joints) {
            if (j.joint == "wheel")
                j.drive = {JointDrive::Mode::Effort, 1.5};
            if (j.joint == "carriage_x")
                j.drive = {JointDrive::Mode::Effort, -4.0};
        }
        UrdfModel urdf(torque_settings);
        Wrench soil;
        soil.force_N = Vec3(2.0, 0.0, 50.0);
        soil.torque_N_m = Vec3(0.0, -0.5, 0.0);
        rig.applyWrenches({soil});
        urdf.applyWrenches({soil});
        compare(rig, urdf, 0.0, 0.4);
        // α = (1.5 - 0.5) / Iyy = 1 / 0.03125 = 32 rad/s²: ω(0.4 s) = 12.8 rad/s (to 1e-9).
        CHECK(urdf.bodyStates()[0].angular_velocity_rad_s.y() == Approx(12.8).margin(1e-9));
        CHECK(urdf.observables().at("wheel_drive_torque_N_m") == 1.5);
    }
    INFO("max differences: position "
         << diff.position << " m, angle " << diff.angle << " rad, velocity " << diff.velocity
         << " m/s, angular velocity " << diff.angular_velocity << " rad/s, drive torque "
         << torque_diff << " N m");
    WARN("URDF vs built-in rig, max differences: position "
         << diff.position << " m, angle " << diff.angle << " rad, velocity " << diff.velocity
         << " m/s, angular velocity " << diff.angular_velocity << " rad/s, drive torque "
         << torque_diff << " N m");
    CHECK(diff.position < tolerance);
    CHECK(diff.angle < tolerance);
    CHECK(diff.velocity < tolerance);
    CHECK(diff.angular_velocity < tolerance);
    CHECK(torque_diff < tolerance);
}

TEST_CASE("URDF model: save/restore and checkpoints keep the drives", "[mbs][urdf]") {
    UrdfModel a(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
    a.applyWrenches({Wrench{}});
    a.advanceTo(0.05);
    a.setDrive("wheel", {JointDrive::Mode::Effort, 0.7});
    const std::string path = "urdf_model_checkpoint.txt";
    a.writeCheckpoint(path);
    UrdfModel b(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
    b.readCheckpoint(path);
    CHECK(b.drive("wheel").mode == JointDrive::Mode::Effort);
    a.advanceTo(0.1);
    b.advanceTo(0.1);
    // Same State, same forces, same integrator: bit-identical.
    CHECK(a.bodyStates()[0].position_m == b.bodyStates()[0].position_m);
    CHECK(a.bodyStates()[0].angular_velocity_rad_s == b.bodyStates()[0].angular_velocity_rad_s);
    std::remove(path.c_str());
}

TEST_CASE("URDF model: a damaged checkpoint is refused naming the file and the line",
          "[mbs][urdf][checkpoint]") {
    UrdfModel a(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
    a.applyWrenches({Wrench{}});
    a.advanceTo(0.02);
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("grainlink-damaged-" + std::to_string(::getpid()) + ".txt"))
                                 .string();
    a.writeCheckpoint(path);
    std::vector<std::string> lines;
    {
        std::ifstream in(path);
        for (std::string line; std::getline(in, line);)
            lines.push_back(line);
    }
    REQUIRE(lines.size() == 5); // t, q, u, wrenches, the drives
    const auto words = [](const std::string &line) {
        std::istringstream in(line);
        std::vector<std::string> out;
        for (std::string w; in >> w;)
            out.push_back(w);
        return out;
    };
    const std::size_t nq = words(lines[1]).size() - 1;
    REQUIRE(nq >= 2);
    // The error reading `damaged` (the intact lines with some replaced or dropped) gives.
    const auto error = [&](std::vector<std::string> damaged) {
        std::ofstream out(path);
        for (const auto &line : damaged)
            out << line << '\n';
        out.close();
        UrdfModel b(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
        return messageOf<ModelError>([&] { b.readCheckpoint(path); });
    };
    {
        UrdfModel b(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
        b.readCheckpoint(path); // the intact file reads
        CHECK(b.time() == a.time());
    }
    CHECK(error({lines[0], lines[1], lines[2]}) ==
          path + ":4: missing the line 'wrenches ...' (the force [N] and torque [N m] on each "
                 "coupled body): truncated multibody checkpoint");
    CHECK(error({lines[0], lines[1], lines[2], lines[3]}) ==
          path + ":5: missing the model's own line: truncated multibody checkpoint");
    // One coordinate fewer: the checkpoint of a model with another number of coordinates.
    std::string short_q = "q";
    for (std::size_t k = 1; k < nq; ++k)
        short_q += " " + words(lines[1])[k];
    CHECK(error({lines[0], short_q, lines[2], lines[3], lines[4]}) ==
          path + ":2: " + std::to_string(nq - 1) + " values of the generalized coordinates, this " +
              "model has " + std::to_string(nq) + " (a checkpoint of another model?)");
    CHECK(error({lines[0], lines[1], lines[2] + " 0.5", lines[3], lines[4]}) ==
          path + ":3: " + std::to_string(words(lines[2]).size()) +
              " values of the generalized speeds, this model has " +
              std::to_string(words(lines[2]).size() - 1) + " (a checkpoint of another model?)");
    CHECK(error({lines[0], lines[1], "u 1 x2", lines[3], lines[4]}) ==
          path + ":3: 'x2' in the generalized speeds is not a finite number");
    CHECK(error({lines[0], lines[1], lines[2], "wrenches 0 0 nan 0 0 0", lines[4]}) ==
          path + ":4: 'nan' in the force [N] and torque [N m] on each coupled body is not a "
                 "finite number");
    CHECK(error({"<robot name=\"rig\">", lines[1]}) ==
          path + ":1: expected 't ...' (the time [s]), got '<robot name=\"rig\">': not a "
                 "multibody checkpoint");
    // The URDF model's own line: drives of joints this model does not have.
    std::string drives = lines[4];
    REQUIRE(drives.find(" wheel ") != std::string::npos);
    drives.replace(drives.find(" wheel "), 7, " axle ");
    CHECK(error({lines[0], lines[1], lines[2], lines[3], drives}) ==
          path + ":5: URDF model checkpoint: drives do not match the model at joint 'wheel'");
    std::remove(path.c_str());
    UrdfModel b(parseUrdfModel(kModels + "/single_wheel_rig.yaml"));
    CHECK(messageOf<ModelError>([&] { b.readCheckpoint(path); }) ==
          "cannot open multibody checkpoint " + path);
}

namespace {

/// A disc on a revolute joint under a base link, with the parts the importer checks left for
/// the caller: the disc's <mass> and <inertia>, the joint's type, its <axis> and extra elements.
std::string discUrdf(const std::string &mass, const std::string &inertia,
                     const std::string &type = "revolute", const std::string &axis = "0 1 0",
                     const std::string &extra = "") {
    return "<?xml version=\"1.0\"?>\n<robot name=\"disc\">\n"
           "  <link name=\"base\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\" "
           "ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial></link>\n"
           "  <link name=\"disc\"><inertial><mass value=\"" +
           mass + "\"/><inertia " + inertia +
           "/></inertial></link>\n"
           "  <link name=\"tip\"/>\n"
           "  <joint name=\"spin\" type=\"" +
           type +
           "\"><parent link=\"base\"/><child link=\"disc\"/>"
           "<axis xyz=\"" +
           axis + "\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>" + extra +
           "</joint>\n"
           "  <joint name=\"tip_weld\" type=\"fixed\"><parent link=\"disc\"/><child "
           "link=\"tip\"/></joint>\n"
           "</robot>\n";
}

const std::string kDiscInertia =
    "ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.01\"";

/// The ModelError building a model from `urdf` (written to a file named `name`) gives, with the
/// file's path replaced by `name`; "(built)" when it builds.
std::string urdfError(const std::string &name, const std::string &urdf) {
    const std::string path =
        (std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "-" + name))
            .string();
    std::ofstream(path) << urdf;
    UrdfModelSettings s;
    s.urdf_path = path;
    std::string message = "(built)";
    try {
        UrdfModel model(s);
    } catch (const ModelError &e) {
        message = e.what();
    }
    std::remove(path.c_str());
    for (std::size_t at; (at = message.find(path)) != std::string::npos;)
        message.replace(at, path.size(), name);
    return message;
}

} // namespace

TEST_CASE("URDF importer: each malformed file is refused naming the file, link or joint",
          "[mbs][urdf]") {
    CHECK(urdfError("disc.urdf", discUrdf("2", kDiscInertia)) == "(built)");
    SECTION("a missing file") {
        UrdfModelSettings s;
        s.urdf_path = kData + "/no_such_model.urdf";
        CHECK(messageOf<ModelError>([&] { UrdfModel m(s); }) ==
              kData + "/no_such_model.urdf: cannot open the URDF file");
    }
    SECTION("a negative or non-finite mass") {
        CHECK(urdfError("negative.urdf", discUrdf("-2", kDiscInertia)) ==
              "negative.urdf: link 'disc': mass must be >= 0, got -2.000000");
    }
    SECTION("a non-finite inertia") {
        // liburdfdom logs these and reads them as 0: iyy = 0 would pass as a physical disc.
        for (const std::string value : {"1e999", "nan", "inf", "heavy"}) {
            std::string inertia = kDiscInertia;
            inertia.replace(inertia.find("0.02"), 4, value);
            CHECK(urdfError("infinite.urdf", discUrdf("2", inertia)) ==
                  "infinite.urdf: not a valid URDF file: Inertial: inertia element iyy is not a "
                  "valid double; Could not parse inertial element for Link [disc]");
        }
        CHECK(urdfError("infinite.urdf", discUrdf("nan", kDiscInertia)) ==
              "infinite.urdf: not a valid URDF file: Inertial: mass [nan] is not a float; "
              "Could not parse inertial element for Link [disc]");
    }
    SECTION("a zero axis") {
        CHECK(urdfError("zero_axis.urdf", discUrdf("2", kDiscInertia, "revolute", "0 0 0")) ==
              "zero_axis.urdf: joint 'spin' has a zero axis");
        CHECK(urdfError("zero_slide.urdf", discUrdf("2", kDiscInertia, "prismatic", "0 0 0")) ==
              "zero_slide.urdf: joint 'spin' has a zero axis");
    }
    SECTION("no root: two links that no joint connects") {
        CHECK_THAT(urdfError("two_roots.urdf",
                             "<robot name=\"x\"><link name=\"a\"/><link name=\"b\"/></robot>"),
                   Catch::StartsWith("two_roots.urdf: not a valid URDF file: ") &&
                       Catch::Contains("root"));
        CHECK_THAT(urdfError("no_links.urdf", "<robot name=\"x\"></robot>"),
                   Catch::StartsWith("no_links.urdf: not a valid URDF file: ") &&
                       Catch::Contains("link"));
    }
    SECTION("a joint type, mimic or friction the importer does not model") {
        CHECK_THAT(urdfError("ball.urdf", discUrdf("2", kDiscInertia, "ball")),
                   Catch::StartsWith("ball.urdf: not a valid URDF file: ") &&
                       Catch::Contains("spin") && Catch::Contains("ball"));
        CHECK(urdfError("mimic.urdf", discUrdf("2", kDiscInertia, "revolute", "0 1 0",
                                               "<mimic joint=\"spin\"/>")) ==
              "mimic.urdf: joint 'spin' mimics another joint: mimic joints are not supported");
        CHECK(urdfError("friction.urdf", discUrdf("2", kDiscInertia, "revolute", "0 1 0",
                                                  "<dynamics friction=\"0.1\"/>")) ==
              "friction.urdf: joint 'spin' has dynamics friction: joint friction is not "
              "modelled; remove it or set it to 0");
        CHECK(urdfError("damping.urdf", discUrdf("2", kDiscInertia, "revolute", "0 1 0",
                                                 "<dynamics damping=\"-0.1\"/>")) ==
              "damping.urdf: joint 'spin': dynamics damping must be >= 0");
    }
}

TEST_CASE("URDF joint springs and a compound pendulum swing at the analytic frequencies",
          "[mbs][urdf]") {
    UrdfModel m(parseUrdfModel(kData + "/oscillators.yaml"));
    // slide: m = 2 kg, k = 50 N/m, x0 = 0.1 m, x(0) = 0.3 m: x = 0.1 + 0.2 cos 5t.
    // twist: I = 0.5 kg m², k = 8 N m/rad, c = 0.4 N m s/rad: γ = c / 2I = 0.4 /s,
    //        ω_d = √(k/I - γ²); θ = 0.3 e^(-γt) (cos ω_d t + γ/ω_d sin ω_d t).
    // swing: I_O = 0.03 + 1.5 · 0.4² = 0.27 kg m², ω0 = √(1.5 · 9.81 · 0.4 / 0.27); at the
    //        amplitude θ0 = 1e-3 rad the pendulum swings at ω0 (1 - θ0²/16) (the first
    //        correction of the large-amplitude period), θ = θ0 cos ωt; left out: the third
    //        harmonic, amplitude θ0³/192 = 5e-12 rad, and O(θ0⁵).
    const double gamma = 0.4, wd = std::sqrt(8.0 / 0.5 - gamma * gamma);
    const double theta0 = 1e-3;
    const double w_pendulum = std::sqrt(1.5 * 9.81 * 0.4 / 0.27) * (1.0 - theta0 * theta0 / 16);
    double err_slide = 0, err_twist = 0, err_swing = 0;
    for (int k = 1; k <= 300; ++k) { // 3 s: 2.4 slider periods, 1.9 pendulum periods
        const double t = 0.01 * k;
        m.advanceTo(t);
        const auto o = m.observables();
        err_slide = std::max(err_slide,
                             std::abs(o.at("slide_position_m") - (0.1 + 0.2 * std::cos(5.0 * t))));
        const double twist =
            0.3 * std::exp(-gamma * t) * (std::cos(wd * t) + gamma / wd * std::sin(wd * t));
        err_twist = std::max(err_twist, std::abs(o.at("twist_position_rad") - twist));
        err_swing = std::max(
            err_swing, std::abs(o.at("swing_position_rad") - theta0 * std::cos(w_pendulum * t)));
    }
    WARN("oscillators, max |error| over 3 s: slide " << err_slide << " m, twist " << err_twist
                                                     << " rad, swing " << err_swing << " rad");
    // Runge-Kutta-Merson at relative accuracy 1e-8 per step; measured over 3 s: 2.5e-12 m,
    // 4e-13 rad and 8e-12 rad (pendulum: mostly the third harmonic left out above). Tolerances
    // 1e-9 m and 1e-9 rad (5e-9 and 3e-9 of the amplitudes) and 5e-11 rad (5e-8 of θ0): a 1 %
    // error in a stiffness, damping,
    // mass or inertia, or the inertial frame's rotation ignored (0.02 kg m² instead of 0.03
    // about the axis: ω off by 2 %), misses by orders of magnitude more.
    CHECK(err_slide < 1e-9);
    CHECK(err_twist < 1e-9);
    CHECK(err_swing < 5e-11);
    // drop: 1 kg falls 0.1 m onto the stop at the URDF's lower limit (k = 1e4 N/m, Hunt-Crossley
    // d = 10 s/m: about 0.5 critical damping at rest) and after 3 s rests where k δ = m g.
    // Measured: 4e-17 m off, settled. Tolerance 1e-9 m (1e-6 of δ = 0.981 mm): a 1 % error in
    // the stiffness or a stop at the wrong limit misses by 1e-5 m or more.
    const auto o = m.observables();
    WARN("stop: rests " << o.at("drop_position_m") - (-0.1 - 9.81 / 1e4)
                        << " m from -0.1 - m g / k, speed " << o.at("drop_speed_m_s") << " m/s");
    CHECK(o.at("drop_position_m") == Approx(-0.1 - 9.81 / 1e4).margin(1e-9));
}

TEST_CASE("URDF floating root with an STL mesh falls under gravity and the soil force",
          "[mbs][urdf]") {
    UrdfModel m(parseUrdfModel(kData + "/free_body.yaml"));
    const auto bodies = m.coupledBodies();
    REQUIRE(bodies.size() == 1);
    CHECK(bodies[0].name == "box");
    const auto *box = std::get_if<MeshShape>(&bodies[0].geometry);
    REQUIRE(box);
    CHECK(box->triangles.size() == 12);
    double extent = 0.0;
    for (const auto &v : box->vertices_m)
        extent = std::max(extent, v.cwiseAbs().maxCoeff());
    CHECK(extent == Approx(0.05).margin(1e-12)); // 50 mm scaled by mesh_scale 0.001
    Wrench soil;
    soil.force_N = Vec3(4.0, 0.0, 19.62); // a = (1, 0, -9.81 + 4.905) m/s²
    m.applyWrenches({soil});
    m.advanceTo(0.5);
    const auto s = m.bodyStates()[0];
    // Constant acceleration: exact to the integrator's accuracy (1e-8 relative): 1e-9 m.
    CHECK(s.position_m.x() == Approx(0.2 + 0.5 * 1.0 * 0.25).margin(1e-9));
    CHECK(s.position_m.y() == Approx(0.1).margin(1e-12));
    CHECK(s.position_m.z() == Approx(2.0 - 0.5 * 4.905 * 0.25).margin(1e-9));
    CHECK(m.observables().at("root_vz_m_s") == Approx(-4.905 * 0.5).margin(1e-9));
}

TEST_CASE("URDF planar joint moves in its plane only, a massless fixed link is allowed",
          "[mbs][urdf]") {
    UrdfModel m(parseUrdfModel(kData + "/planar.yaml"));
    Wrench soil;
    soil.force_N = Vec3(3.0, 5.0, 0.0);    // y is normal to the plane: carried by the joint
    soil.torque_N_m = Vec3(0.2, 0.1, 0.3); // only the y component turns the puck
    m.applyWrenches({soil});
    m.advanceTo(0.4);
    const auto s = m.bodyStates()[0];
    // Constant accelerations a_x = 3 / 2, a_z = -9.81, α_y = 0.1 / 0.05 (Iyy): exact to the
    // integrator's accuracy (1e-8 relative): 1e-9.
    CHECK(s.position_m.x() == Approx(0.5 * 1.5 * 0.16).margin(1e-9));
    CHECK(s.position_m.y() == Approx(0.0).margin(1e-12));
    CHECK(s.position_m.z() == Approx(1.0 - 0.5 * 9.81 * 0.16).margin(1e-9));
    CHECK(s.angular_velocity_rad_s.y() == Approx(2.0 * 0.4).margin(1e-9));
    CHECK(s.angular_velocity_rad_s.x() == Approx(0.0).margin(1e-12));
    CHECK(s.angular_velocity_rad_s.z() == Approx(0.0).margin(1e-12));
    CHECK(m.observables().at("sled_angle_rad") == Approx(0.5 * 2.0 * 0.16).margin(1e-9));
}

TEST_CASE("URDF and YAML errors name the file, the key and the line", "[mbs][urdf]") {
    SECTION("a URDF that is not valid XML") {
        UrdfModelSettings s;
        s.urdf_path = kData + "/bad_xml.urdf";
        const std::string msg = messageOf<ModelError>([&] { UrdfModel m(s); });
        CHECK_THAT(msg, Catch::Contains("bad_xml.urdf") && Catch::Contains("not a valid URDF"));
        const std::string yaml =
            messageOf<ConfigError>([&] { parseUrdfModel(kData + "/bad_xml.yaml"); });
        CHECK_THAT(yaml, Catch::Contains("bad_xml.yaml:2: key 'urdf'") &&
                             Catch::Contains("bad_xml.urdf"));
    }
    SECTION("a joint naming a link that does not exist") {
        UrdfModelSettings s;
        s.urdf_path = kData + "/missing_link.urdf";
        const std::string msg = messageOf<ModelError>([&] { UrdfModel m(s); });
        CHECK_THAT(msg, Catch::Contains("missing_link.urdf") && Catch::Contains("hub"));
    }
    SECTION("a YAML naming a link the URDF lacks") {
        const std::string msg =
            messageOf<ConfigError>([&] { parseUrdfModel(kData + "/missing_coupled_link.yaml"); });
        CHECK_THAT(msg, Catch::Contains("missing_coupled_link.yaml:5: key 'coupled[0].link'") &&
                            Catch::Contains("no link 'tyre'"));
    }
    SECTION("a YAML naming a joint the URDF lacks") {
        const std::string msg =
            messageOf<ConfigError>([&] { parseUrdfModel(kData + "/missing_joint.yaml"); });
        CHECK_THAT(msg, Catch::Contains("missing_joint.yaml:8: key 'joints[1].joint'") &&
                            Catch::Contains("no joint 'axle'"));
    }
    SECTION("a revolute joint's position in metres") {
        const std::string msg =
            messageOf<ConfigError>([&] { parseUrdfModel(kData + "/wrong_unit.yaml"); });
        CHECK_THAT(msg, Catch::Contains("wrong_unit.yaml:5: unknown key 'joints[0].position_m'"));
    }
    SECTION("a spring's rest position without a stiffness, which would change nothing") {
        const std::string msg = messageOf<ConfigError>(
            [&] { parseUrdfModel(kData + "/spring_rest_without_stiffness.yaml"); });
        CHECK_THAT(msg, Catch::Contains("spring_rest_without_stiffness.yaml:6: key "
                                        "'joints[0].spring.rest_position_m'") &&
                            Catch::Contains("no rest position"));
    }
    SECTION("a massless link at the end of a moving joint") {
        UrdfModelSettings s;
        s.urdf_path = kData + "/massless_terminal.urdf";
        const std::string msg = messageOf<ModelError>([&] { UrdfModel m(s); });
        CHECK_THAT(msg, Catch::Contains("massless_terminal.urdf") &&
                            Catch::Contains("link 'probe'") && Catch::Contains("no mass"));
    }
    SECTION("an inertia tensor that no body has") {
        UrdfModelSettings s;
        s.urdf_path = kData + "/bad_inertia.urdf";
        const std::string msg = messageOf<ModelError>([&] { UrdfModel m(s); });
        CHECK_THAT(msg, Catch::Contains("bad_inertia.urdf: link 'disc'") &&
                            Catch::Contains("not physical"));
    }
    SECTION("a stop on a joint without limits") {
        const std::string msg =
            messageOf<ConfigError>([&] { parseUrdfModel(kData + "/stop_without_limits.yaml"); });
        CHECK_THAT(msg, Catch::Contains("stop_without_limits.yaml:5: key 'joints[0].stop'") &&
                            Catch::Contains("no position limits"));
    }
    SECTION("settings built in code naming a missing joint") {
        UrdfModelSettings s;
        s.urdf_path = kModels + "/single_wheel_rig.urdf";
        UrdfJointSettings j;
        j.joint = "axle";
        s.joints.push_back(j);
        const std::string msg = messageOf<ModelError>([&] { UrdfModel m(s); });
        CHECK_THAT(msg, Catch::Contains("joint 'axle'"));
    }
}
