#include "grainlink/mbs/UrdfModel.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/TriangleMesh.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

namespace grainlink::mbs {

namespace {

namespace fs = std::filesystem;
using config::ConfigNode;

// ---------------------------------------------------------------------------------------------
// Reading the URDF

/// liburdfdom reports why a file does not parse through console_bridge; the messages are
/// collected here so that the exception can carry them.
class CollectErrors : public console_bridge::OutputHandler {
public:
    void log(const std::string &text, console_bridge::LogLevel level, const char *, int) override {
        if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
            messages += (messages.empty() ? "" : "; ") + text;
    }
    std::string messages;
};

urdf::ModelInterfaceSharedPtr loadUrdf(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw ModelError(path + ": cannot open the URDF file");
    std::stringstream text;
    text << in.rdbuf();
    // console_bridge's handler is process-wide: one parse at a time.
    static std::mutex mutex;
    std::lock_guard<std::mutex> lock(mutex);
    CollectErrors errors;
    console_bridge::useOutputHandler(&errors);
    urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
    console_bridge::restorePreviousOutputHandler();
    // liburdfdom returns a model even when it could not parse an element (an <inertia> of
    // "nan" or "1e999" it logs and then reads as 0): an error logged is a refusal too.
    if (!model || !errors.messages.empty())
        throw ModelError(path + ": not a valid URDF file: " +
                         (errors.messages.empty() ? "liburdfdom gave no reason" : errors.messages));
    return model;
}

enum class Kind { Rotational, Translational, Other };

Kind kindOf(const urdf::Joint &joint) {
    switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
        return Kind::Rotational;
    case urdf::Joint::PRISMATIC:
        return Kind::Translational;
    default:
        return Kind::Other;
    }
}

std::string typeName(const urdf::Joint &joint) {
    switch (joint.type) {
    case urdf::Joint::REVOLUTE:
        return "revolute";
    case urdf::Joint::CONTINUOUS:
        return "continuous";
    case urdf::Joint::PRISMATIC:
        return "prismatic";
    case urdf::Joint::FLOATING:
        return "floating";
    case urdf::Joint::PLANAR:
        return "planar";
    case urdf::Joint::FIXED:
        return "fixed";
    default:
        return "unknown";
    }
}

/// Key suffixes of a one-dof joint's quantities (docs/user-models.md).
struct Units {
    const char *position, *velocity, *speed, *effort, *stiffness, *damping, *rest, *dissipation;
};
const Units kRotational{"position_rad",      "velocity_rad_s",    "speed_rad_s",
                        "torque_N_m",        "stiffness_N_m_rad", "damping_N_m_s_rad",
                        "rest_position_rad", "dissipation_s_rad"};
const Units kTranslational{"position_m",    "velocity_m_s",  "speed_m_s",       "force_N",
                           "stiffness_N_m", "damping_N_s_m", "rest_position_m", "dissipation_s_m"};

SimTK::Vec3 toSimTK(const urdf::Vector3 &v) {
    return SimTK::Vec3(v.x, v.y, v.z);
}
SimTK::Rotation toSimTK(const urdf::Rotation &r) {
    return SimTK::Rotation(SimTK::Quaternion(r.w, r.x, r.y, r.z));
}
SimTK::Transform toSimTK(const urdf::Pose &pose) {
    return SimTK::Transform(toSimTK(pose.rotation), toSimTK(pose.position));
}

/// Mass properties of a link about its frame's origin, in its frame. The URDF gives the
/// inertia about the centre of mass in the <inertial> frame (rotated by its rpy):
/// I_B = R I R^T, then shifted to the link origin by I_o = I_B + m (|c|² E - c cᵀ)
/// (docs/physics.md §11). A link without <inertial> is massless.
struct LinkMass {
    double mass_kg = 0.0;
    Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero(); ///< [kg m²] about the com, link frame
};

LinkMass massOf(const urdf::Link &link, const std::string &urdf_path) {
    LinkMass out;
    if (!link.inertial)
        return out;
    const urdf::Inertial &in = *link.inertial;
    const std::string where = urdf_path + ": link '" + link.name + "': ";
    if (!std::isfinite(in.mass) || in.mass < 0.0)
        throw ModelError(where + "mass must be >= 0, got " + std::to_string(in.mass));
    Eigen::Matrix3d inertia;
    inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    if (!inertia.allFinite())
        throw ModelError(where + "the inertia tensor has a non-finite entry");
    const Eigen::Vector3d moments =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues(); // ascending
    const double scale = std::max(1e-300, moments.cwiseAbs().maxCoeff());
    // A physical inertia has non-negative principal moments obeying the triangle inequality.
    if (moments[0] < -1e-12 * scale || moments[0] + moments[1] < moments[2] * (1.0 - 1e-9)) {
        std::ostringstream os;
        os << where << "the inertia tensor is not physical (principal moments " << moments[0]
           << ", " << moments[1] << ", " << moments[2]
           << " kg m²: each must be >= 0 and none larger than the other two together)";
        throw ModelError(os.str());
    }
    if (in.mass == 0.0) {
        if (moments[2] > 0.0)
            throw ModelError(where + "zero mass with a nonzero inertia");
        return out;
    }
    const urdf::Rotation &q = in.origin.rotation;
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    out.mass_kg = in.mass;
    out.com_m = Eigen::Vector3d(in.origin.position.x, in.origin.position.y, in.origin.position.z);
    out.inertia_com = R * inertia * R.transpose();
    return out;
}

SimTK::MassProperties simbodyMass(const LinkMass &m) {
    if (m.mass_kg == 0.0)
        return SimTK::MassProperties(0, SimTK::Vec3(0), SimTK::Inertia(0));
    const Eigen::Vector3d &c = m.com_m;
    // Parallel-axis shift to the link origin (docs/physics.md §11).
    const Eigen::Matrix3d I =
        m.inertia_com +
        m.mass_kg * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    const SimTK::Inertia inertia(SimTK::Vec3(I(0, 0), I(1, 1), I(2, 2)),
                                 SimTK::Vec3(I(0, 1), I(0, 2), I(1, 2)));
    return SimTK::MassProperties(m.mass_kg, SimTK::Vec3(c.x(), c.y(), c.z()), inertia);
}

/// Mass of a link and every link below it.
double subtreeMass(const urdf::Link &link, const std::string &urdf_path) {
    double m = massOf(link, urdf_path).mass_kg;
    for (const auto &child : link.child_links)
        m += subtreeMass(*child, urdf_path);
    return m;
}

/// A rotation R_JA whose `axis` (x or z) is `direction` in J: the mobilizer's axis frames.
SimTK::Rotation axisFrame(const urdf::Joint &joint, SimTK::CoordinateAxis axis,
                          const std::string &urdf_path) {
    const SimTK::Vec3 d(joint.axis.x, joint.axis.y, joint.axis.z);
    if (!(d.norm() > 1e-12) || !d.isFinite())
        throw ModelError(urdf_path + ": joint '" + joint.name + "' has a zero axis");
    return SimTK::Rotation(SimTK::UnitVec3(d), axis);
}

std::string where(const UrdfModelSettings &s) {
    return s.yaml_path.empty() ? s.urdf_path : s.yaml_path;
}

/// A name in the settings that the URDF lacks (parseUrdfModel reports these with the line;
/// this is for settings built in code, or a URDF changed after parsing).
ModelError notInUrdf(const UrdfModelSettings &s, const std::string &what) {
    if (s.yaml_path.empty())
        return ModelError(s.urdf_path + ": the model settings name " + what +
                          ", which this URDF does not have");
    return ModelError(s.yaml_path + ": " + what + " is not in the URDF " + s.urdf_path);
}

MeshShape readMesh(const ConfigNode &item, const fs::path &folder) {
    const ConfigNode file = item["mesh_file"];
    const fs::path path = (folder / file.text()).lexically_normal();
    const double scale = item.has("mesh_scale") ? item["mesh_scale"].positive() : 1.0;
    dem::TriangleMesh mesh;
    try {
        mesh = dem::readStl(path.string());
        mesh.transform(scale, dem::Vec3::Zero());
        mesh.validate(path.string());
    } catch (const std::exception &e) {
        file.fail(std::string("cannot use the mesh: ") + e.what());
    }
    if (mesh.triangles.empty())
        file.fail("the mesh " + path.string() + " has no triangles");
    MeshShape out;
    for (const auto &v : mesh.vertices_m)
        out.vertices_m.emplace_back(v.x(), v.y(), v.z());
    out.triangles = mesh.triangles;
    return out;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// The YAML

UrdfModelSettings parseUrdfModel(const std::string &yaml_path) {
    const ConfigNode root = ConfigNode::loadFile(yaml_path);
    const fs::path folder = fs::path(yaml_path).parent_path();
    UrdfModelSettings s;
    s.yaml_path = yaml_path;
    const ConfigNode urdf_key = root["urdf"];
    s.urdf_path = (folder / urdf_key.text()).lexically_normal().string();
    urdf::ModelInterfaceSharedPtr model;
    try {
        model = loadUrdf(s.urdf_path);
    } catch (const ModelError &e) {
        urdf_key.fail(e.what());
    }
    if (auto g = root.optional("gravity_m_s2"))
        s.gravity_m_s2 = g->vec3();

    if (auto r = root.optional("root")) {
        s.root_floating = r->boolean("floating", false);
        if (auto p = r->optional("position_m"))
            s.root_position_m = p->vec3();
        if (auto p = r->optional("rpy_rad"))
            s.root_rpy_rad = p->vec3();
        r->finish();
    }

    if (auto coupled = root.optional("coupled")) {
        std::set<std::string> seen;
        for (const ConfigNode &item : coupled->items()) {
            UrdfCoupledLink c;
            const ConfigNode link = item["link"];
            c.link = link.text();
            if (!model->getLink(c.link))
                link.fail("no link '" + c.link + "' in " + s.urdf_path);
            c.name = item.text("name", c.link);
            if (!seen.insert(c.name).second)
                item.fail("a second coupled body named '" + c.name + "'");
            const bool wheel = item.has("wheel"), mesh = item.has("mesh_file");
            if (wheel == mesh)
                item.fail("give exactly one of 'wheel' (a parametric wheel) or 'mesh_file' (STL)");
            if (wheel)
                c.geometry = parseWheelShape(item["wheel"]);
            else
                c.geometry = readMesh(item, folder);
            item.finish();
            s.coupled.push_back(std::move(c));
        }
    }

    if (auto joints = root.optional("joints")) {
        std::set<std::string> seen;
        for (const ConfigNode &item : joints->items()) {
            UrdfJointSettings j;
            const ConfigNode name = item["joint"];
            j.joint = name.text();
            const urdf::JointConstSharedPtr joint = model->getJoint(j.joint);
            if (!joint)
                name.fail("no joint '" + j.joint + "' in " + s.urdf_path);
            if (!seen.insert(j.joint).second)
                name.fail("joint '" + j.joint + "' appears twice");
            const Kind kind = kindOf(*joint);
            if (kind == Kind::Other)
                name.fail("joint '" + j.joint + "' is " + typeName(*joint) +
                          ": only revolute, continuous and prismatic joints take initial "
                          "values, drives and springs");
            const Units &u = kind == Kind::Rotational ? kRotational : kTranslational;
            if (auto p = item.optional(u.position))
                j.position = p->number();
            if (auto v = item.optional(u.velocity))
                j.velocity = v->number();
            if (auto d = item.optional("drive")) {
                const std::string mode = (*d)["mode"].choice({"none", "speed", "effort", "locked"});
                if (mode == "speed") {
                    j.drive = {JointDrive::Mode::Speed, (*d)[u.speed].number()};
                } else if (mode == "effort") {
                    j.drive = {JointDrive::Mode::Effort, (*d)[u.effort].number()};
                } else if (mode == "locked") {
                    j.drive = {JointDrive::Mode::Locked, 0.0};
                }
                d->finish();
                if (j.velocity && j.drive.mode != JointDrive::Mode::None &&
                    j.drive.mode != JointDrive::Mode::Effort)
                    item[u.velocity].fail("a speed drive or a lock sets the joint's speed; "
                                          "remove this key");
            }
            if (auto sp = item.optional("spring")) {
                JointSpring spring;
                if (const auto k = sp->optional(u.stiffness))
                    spring.stiffness = k->nonNegative();
                if (const auto c = sp->optional(u.damping))
                    spring.damping = c->nonNegative();
                spring.rest_position = sp->number(u.rest, 0.0);
                if (spring.stiffness == 0.0 && sp->has(u.rest))
                    (*sp)[u.rest].fail(std::string("a spring without stiffness has no rest "
                                                   "position: give ") +
                                       u.stiffness + " or remove the key");
                sp->finish();
                j.spring = spring;
            }
            if (auto st = item.optional("stop")) {
                if (joint->type == urdf::Joint::CONTINUOUS || !joint->limits)
                    st->fail("joint '" + j.joint +
                             "' has no position limits in the URDF to stop at");
                JointStop stop;
                stop.stiffness = (*st)[u.stiffness].positive();
                if (const auto d = st->optional(u.dissipation))
                    stop.dissipation = d->nonNegative();
                st->finish();
                j.stop = stop;
            }
            item.finish();
            s.joints.push_back(std::move(j));
        }
    }

    if (auto integrator = root.optional("integrator")) {
        s.integrator.accuracy = integrator->number("accuracy", s.integrator.accuracy);
        s.integrator.max_step_s = integrator->number("max_step_s", s.integrator.max_step_s);
        integrator->finish();
    }
    root.finish();
    return s;
}

// ---------------------------------------------------------------------------------------------
// The model

struct UrdfModel::Joint {
    std::string name;
    std::string type;
    Kind kind = Kind::Other;
    SimTK::MobilizedBody mobod;
    SimTK::Constraint::ConstantSpeed speed; ///< one-dof joints only; disabled unless driven
    JointDrive drive;
};

UrdfModel::~UrdfModel() = default;

UrdfModel::UrdfModel(const UrdfModelSettings &settings)
    : SimbodyModel(settings.gravity_m_s2, settings.integrator), settings_(settings) {
    const std::string &path = settings_.urdf_path;
    const urdf::ModelInterfaceSharedPtr model = loadUrdf(path);
    const urdf::LinkConstSharedPtr root = model->getRoot();
    if (!root)
        throw ModelError(path + ": the URDF has no root link");

    // Every name the settings use exists (parseUrdfModel checked them with lines already; a
    // model built from settings in code is checked here).
    for (const auto &c : settings_.coupled)
        if (!model->getLink(c.link))
            throw notInUrdf(settings_, "coupled link '" + c.link + "'");
    for (const auto &j : settings_.joints) {
        const auto joint = model->getJoint(j.joint);
        if (!joint)
            throw notInUrdf(settings_, "joint '" + j.joint + "'");
        if (kindOf(*joint) == Kind::Other)
            throw ModelError((settings_.yaml_path.empty() ? path : settings_.yaml_path) +
                             ": joint '" + j.joint + "' is " + typeName(*joint) +
                             ": only one-dof joints take settings");
    }

    // A mobilizer that moves a body needs mass below it: Simbody cannot accelerate nothing.
    auto needMass = [&](const urdf::Link &link, const std::string &what) {
        if (subtreeMass(link, path) <= 0.0)
            throw ModelError(path + ": link '" + link.name + "' (" + what +
                             ") has no mass and no link with mass below it, so Simbody cannot "
                             "move it; give it an <inertial> with a positive mass, or make its "
                             "joint fixed");
    };
    if (settings_.root_floating)
        needMass(*root, "the floating root");

    // Root: welded to Ground, or free, at the pose the settings give.
    urdf::Pose root_pose;
    root_pose.position = urdf::Vector3(settings_.root_position_m.x(), settings_.root_position_m.y(),
                                       settings_.root_position_m.z());
    root_pose.rotation.setFromRPY(settings_.root_rpy_rad.x(), settings_.root_rpy_rad.y(),
                                  settings_.root_rpy_rad.z());
    const SimTK::Body::Rigid root_body(simbodyMass(massOf(*root, path)));
    std::map<std::string, SimTK::MobilizedBody> bodies;
    if (settings_.root_floating) {
        Joint j;
        j.name = "root";
        j.type = "floating";
        j.mobod = SimTK::MobilizedBody::Free(matter_.Ground(), toSimTK(root_pose), root_body,
                                             SimTK::Transform());
        bodies[root->name] = j.mobod;
        joints_.push_back(std::move(j));
    } else {
        bodies[root->name] = SimTK::MobilizedBody::Weld(matter_.Ground(), toSimTK(root_pose),
                                                        root_body, SimTK::Transform());
    }

    // Joints, parents before children. The child link's frame is the joint frame J (URDF);
    // the mobilizer frames F (on the parent) and M (on the child) are J turned so that the
    // joint axis becomes Simbody's: z for Pin and Planar, x for Slider. At q = 0, F = M and
    // the child sits at the joint origin, as in the URDF.
    std::vector<urdf::LinkConstSharedPtr> pending{root};
    while (!pending.empty()) {
        const urdf::LinkConstSharedPtr parent = pending.back();
        pending.pop_back();
        for (const auto &joint : parent->child_joints) {
            const urdf::LinkConstSharedPtr child = model->getLink(joint->child_link_name);
            if (joint->mimic)
                throw ModelError(path + ": joint '" + joint->name +
                                 "' mimics another joint: mimic joints are not supported");
            if (joint->dynamics && joint->dynamics->friction != 0.0)
                throw ModelError(path + ": joint '" + joint->name +
                                 "' has dynamics friction: joint friction is not modelled; "
                                 "remove it or set it to 0");
            const SimTK::Transform X_PJ = toSimTK(joint->parent_to_joint_origin_transform);
            const SimTK::Body::Rigid body(simbodyMass(massOf(*child, path)));
            SimTK::MobilizedBody P = bodies.at(parent->name); // a handle: shares the body
            Joint j;
            j.name = joint->name;
            j.type = typeName(*joint);
            j.kind = kindOf(*joint);
            switch (joint->type) {
            case urdf::Joint::REVOLUTE:
            case urdf::Joint::CONTINUOUS: {
                needMass(*child, "child of joint '" + joint->name + "'");
                const SimTK::Rotation R = axisFrame(*joint, SimTK::ZAxis, path);
                j.mobod = SimTK::MobilizedBody::Pin(P, X_PJ * SimTK::Transform(R), body,
                                                    SimTK::Transform(R));
                break;
            }
            case urdf::Joint::PRISMATIC: {
                needMass(*child, "child of joint '" + joint->name + "'");
                const SimTK::Rotation R = axisFrame(*joint, SimTK::XAxis, path);
                j.mobod = SimTK::MobilizedBody::Slider(P, X_PJ * SimTK::Transform(R), body,
                                                       SimTK::Transform(R));
                break;
            }
            case urdf::Joint::PLANAR: {
                needMass(*child, "child of joint '" + joint->name + "'");
                const SimTK::Rotation R = axisFrame(*joint, SimTK::ZAxis, path);
                j.mobod = SimTK::MobilizedBody::Planar(P, X_PJ * SimTK::Transform(R), body,
                                                       SimTK::Transform(R));
                break;
            }
            case urdf::Joint::FLOATING:
                needMass(*child, "child of joint '" + joint->name + "'");
                j.mobod = SimTK::MobilizedBody::Free(P, X_PJ, body, SimTK::Transform());
                break;
            case urdf::Joint::FIXED:
                j.mobod = SimTK::MobilizedBody::Weld(P, X_PJ, body, SimTK::Transform());
                break;
            default:
                throw ModelError(path + ": joint '" + joint->name + "' has an unknown type");
            }
            if (j.kind != Kind::Other) {
                j.speed = SimTK::Constraint::ConstantSpeed(j.mobod, 0.0);
                j.speed.setDisabledByDefault(true);
                // URDF <dynamics damping>: viscous joint damping (docs/physics.md §11).
                if (joint->dynamics && joint->dynamics->damping != 0.0) {
                    if (!(joint->dynamics->damping > 0.0))
                        throw ModelError(path + ": joint '" + joint->name +
                                         "': dynamics damping must be >= 0");
                    SimTK::Force::MobilityLinearDamper(forces_, j.mobod, SimTK::MobilizerUIndex(0),
                                                       joint->dynamics->damping);
                }
            }
            bodies[child->name] = j.mobod;
            if (j.type != "fixed")
                joints_.push_back(std::move(j));
            pending.push_back(child);
        }
    }

    // Drives, stops and springs (docs/physics.md §11); spring: f = -k (q - q0) - c u.
    for (const auto &js : settings_.joints) {
        Joint &j = jointNamed(js.joint);
        j.drive = js.drive;
        if (js.stop) {
            // Compliant stop at the URDF limits (docs/physics.md §11).
            const auto joint = model->getJoint(js.joint);
            if (joint->type == urdf::Joint::CONTINUOUS || !joint->limits ||
                !(joint->limits->lower <= joint->limits->upper))
                throw ModelError(path + ": joint '" + js.joint +
                                 "' has no position limits (lower <= upper) to stop at");
            if (!(js.stop->stiffness > 0.0) || !(js.stop->dissipation >= 0.0))
                throw ModelError(where(settings_) + ": joint '" + js.joint +
                                 "': a stop needs stiffness > 0 and dissipation >= 0");
            SimTK::Force::MobilityLinearStop(forces_, j.mobod, SimTK::MobilizerQIndex(0),
                                             js.stop->stiffness, js.stop->dissipation,
                                             joint->limits->lower, joint->limits->upper);
        }
        if (!js.spring)
            continue;
        if (js.spring->stiffness != 0.0)
            SimTK::Force::MobilityLinearSpring(forces_, j.mobod, SimTK::MobilizerUIndex(0),
                                               js.spring->stiffness, js.spring->rest_position);
        if (js.spring->damping != 0.0)
            SimTK::Force::MobilityLinearDamper(forces_, j.mobod, SimTK::MobilizerUIndex(0),
                                               js.spring->damping);
    }

    for (const auto &c : settings_.coupled) {
        const LinkMass m = massOf(*model->getLink(c.link), path);
        BodyDescription body;
        body.name = c.name;
        body.mass.mass_kg = m.mass_kg;
        body.mass.center_of_mass_m = m.com_m;
        body.mass.inertia_diagonal_kg_m2 = m.inertia_com.diagonal();
        body.mass.inertia_off_diagonal_kg_m2 =
            Vec3(m.inertia_com(0, 1), m.inertia_com(0, 2), m.inertia_com(1, 2));
        body.geometry = c.geometry;
        addCoupled(body, bodies.at(c.link));
    }

    try {
        finishBuilding();
        SimTK::State &st = state();
        for (const auto &js : settings_.joints) {
            Joint &j = jointNamed(js.joint);
            if (js.position)
                j.mobod.setOneQ(st, SimTK::MobilizerQIndex(0), *js.position);
            if (js.velocity)
                j.mobod.setOneU(st, SimTK::MobilizerUIndex(0), *js.velocity);
        }
        for (auto &j : joints_)
            if (j.kind != Kind::Other)
                applyDrive(j);
        // Realized once to acceleration: a singular mass matrix shows here, not mid-run.
        system_.realize(st, SimTK::Stage::Acceleration);
    } catch (const SimTK::Exception::Base &e) {
        throw ModelError(path + ": Simbody cannot build this model: " + e.getMessage());
    }
    saveState();
}

UrdfModel::Joint &UrdfModel::jointNamed(const std::string &name) {
    for (auto &j : joints_)
        if (j.name == name && j.kind != Kind::Other)
            return j;
    throw notInUrdf(settings_, "revolute, continuous or prismatic joint '" + name + "'");
}

const UrdfModel::Joint &UrdfModel::jointNamed(const std::string &name) const {
    return const_cast<UrdfModel *>(this)->jointNamed(name);
}

void UrdfModel::applyDrive(Joint &j) {
    SimTK::State &st = state();
    const SimTK::MobilizerUIndex u0(0);
    const bool speed =
        j.drive.mode == JointDrive::Mode::Speed || j.drive.mode == JointDrive::Mode::Locked;
    if (speed) {
        const double v = j.drive.mode == JointDrive::Mode::Speed ? j.drive.value : 0.0;
        if (j.speed.isDisabled(st))
            j.speed.enable(st);
        j.speed.setSpeed(st, v);
        j.mobod.setOneU(st, u0, v);
        discrete_.setOneMobilityForce(st, j.mobod, u0, 0.0);
    } else {
        if (!j.speed.isDisabled(st))
            j.speed.disable(st);
        const double effort = j.drive.mode == JointDrive::Mode::Effort ? j.drive.value : 0.0;
        discrete_.setOneMobilityForce(st, j.mobod, u0, effort);
    }
    system_.realize(st, SimTK::Stage::Velocity);
}

void UrdfModel::setDrive(const std::string &joint, const JointDrive &drive) {
    Joint &j = jointNamed(joint);
    j.drive = drive;
    applyDrive(j);
}

JointDrive UrdfModel::drive(const std::string &joint) const {
    return jointNamed(joint).drive;
}

std::vector<std::string> UrdfModel::jointNames() const {
    std::vector<std::string> names;
    for (const auto &j : joints_)
        names.push_back(j.name);
    return names;
}

std::map<std::string, double> UrdfModel::observables() const {
    const SimTK::State &st = state();
    system_.realize(st, SimTK::Stage::Acceleration);
    std::map<std::string, double> o;
    for (const auto &j : joints_) {
        if (j.kind != Kind::Other) {
            const Units &u = j.kind == Kind::Rotational ? kRotational : kTranslational;
            const std::string speed_unit = std::string(u.velocity).substr(9); // after "velocity_"
            o[j.name + "_" + u.position] = j.mobod.getOneQ(st, SimTK::MobilizerQIndex(0));
            o[j.name + "_speed_" + speed_unit] = j.mobod.getOneU(st, SimTK::MobilizerUIndex(0));
            // The effort the drive applies; a Lagrange multiplier has the opposite sign.
            if (j.drive.mode == JointDrive::Mode::Effort)
                o[j.name + "_drive_" + u.effort] = j.drive.value;
            else if (j.drive.mode != JointDrive::Mode::None)
                o[j.name + "_drive_" + u.effort] = -j.speed.getMultiplier(st);
        } else if (j.type == "planar") {
            o[j.name + "_angle_rad"] = j.mobod.getOneQ(st, SimTK::MobilizerQIndex(0));
            o[j.name + "_x_m"] = j.mobod.getOneQ(st, SimTK::MobilizerQIndex(1));
            o[j.name + "_y_m"] = j.mobod.getOneQ(st, SimTK::MobilizerQIndex(2));
            o[j.name + "_angular_speed_rad_s"] = j.mobod.getOneU(st, SimTK::MobilizerUIndex(0));
            o[j.name + "_vx_m_s"] = j.mobod.getOneU(st, SimTK::MobilizerUIndex(1));
            o[j.name + "_vy_m_s"] = j.mobod.getOneU(st, SimTK::MobilizerUIndex(2));
        } else { // floating: the child's frame in the joint frame
            const SimTK::Transform X = j.mobod.getMobilizerTransform(st);
            const SimTK::SpatialVec V = j.mobod.getMobilizerVelocity(st);
            const char *axes[3] = {"x", "y", "z"};
            for (int k = 0; k < 3; ++k) {
                o[j.name + "_" + axes[k] + "_m"] = X.p()[k];
                o[j.name + "_v" + axes[k] + "_m_s"] = V[1][k];
                o[j.name + "_w" + axes[k] + "_rad_s"] = V[0][k];
            }
        }
    }
    return o;
}

std::string UrdfModel::checkpointExtras() const {
    // The drives may change between windows (setDrive): one "name mode value" per joint.
    std::ostringstream os;
    os.precision(17);
    os << "drives";
    for (const auto &j : joints_)
        if (j.kind != Kind::Other)
            os << ' ' << j.name << ' ' << static_cast<int>(j.drive.mode) << ' ' << j.drive.value;
    return os.str();
}

void UrdfModel::readCheckpointExtras(const std::string &line) {
    std::istringstream in(line);
    std::string tag;
    if (!(in >> tag) || tag != "drives")
        throw ModelError("URDF model checkpoint: expected 'drives ...', got '" + line + "'");
    SimTK::State &st = state();
    for (auto &j : joints_) {
        if (j.kind == Kind::Other)
            continue;
        std::string name;
        int mode = 0;
        double value = 0.0;
        if (!(in >> name >> mode >> value) || name != j.name || mode < 0 || mode > 3)
            throw ModelError("URDF model checkpoint: drives do not match the model at joint '" +
                             j.name + "'");
        j.drive = {static_cast<JointDrive::Mode>(mode), value};
        // Re-impose the drive on the restored speed without changing it.
        const double u = j.mobod.getOneU(st, SimTK::MobilizerUIndex(0));
        applyDrive(j);
        j.mobod.setOneU(st, SimTK::MobilizerUIndex(0), u);
    }
    system_.realize(st, SimTK::Stage::Velocity);
}

} // namespace grainlink::mbs
