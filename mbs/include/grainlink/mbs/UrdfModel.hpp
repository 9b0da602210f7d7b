#pragma once
// A user's mechanism read from a URDF file (parsed by liburdfdom) and a small YAML file beside
// it that says which links touch the soil, which joints are driven and how, the joint springs
// and the initial joint state (docs/user-models.md). Links become Simbody bodies, joints become
// mobilizers: revolute/continuous -> Pin, prismatic -> Slider, fixed -> Weld,
// floating -> Free, planar -> Planar. Adding a mechanism needs no recompilation.
#include "grainlink/mbs/SimbodyModel.hpp"

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace grainlink::mbs {

/// How a joint is actuated. Speeds and efforts are in the joint's own unit: rad/s and N m for
/// revolute and continuous joints, m/s and N for prismatic ones.
struct JointDrive {
    enum class Mode { None, Speed, Effort, Locked };
    Mode mode = Mode::None;
    double value = 0.0; ///< [rad/s | m/s] for Speed, [N m | N] for Effort
};

/// A linear spring and damper on a one-dof joint (docs/physics.md §11).
struct JointSpring {
    double stiffness = 0.0;     ///< [N m/rad | N/m]
    double damping = 0.0;       ///< [N m s/rad | N s/m]
    double rest_position = 0.0; ///< [rad | m] where the spring force is zero
};

/// A compliant stop at the URDF's position limits (<limit lower upper>) of a revolute or
/// prismatic joint; without one the limits are not enforced (docs/physics.md §11).
struct JointStop {
    double stiffness = 0.0;   ///< [N m/rad | N/m] per unit of limit violation
    double dissipation = 0.0; ///< [s/rad | s/m] Hunt-Crossley coefficient
};

/// What the YAML says about one joint of the URDF.
struct UrdfJointSettings {
    std::string joint;
    std::optional<double> position; ///< [rad | m] initial coordinate (URDF zero if absent)
    std::optional<double> velocity; ///< [rad/s | m/s] initial speed
    JointDrive drive;
    std::optional<JointSpring> spring;
    std::optional<JointStop> stop;
};

/// A link that touches the soil, with its geometry in the link frame.
struct UrdfCoupledLink {
    std::string link;
    std::string name;              ///< name on the wire; the link name unless given
    /// A parametric wheel (axis = link y, centre = link origin) or an STL read at parse time.
    std::variant<std::monostate, MeshShape, WheelShape> geometry;
};

struct UrdfModelSettings {
    std::string urdf_path; ///< resolved against the YAML file's folder
    std::string yaml_path; ///< the settings' own file, for messages ("" if built in code)
    Vec3 gravity_m_s2 = Vec3(0, 0, -9.81);
    bool root_floating = false;           ///< root link on a Free mobilizer instead of welded
    Vec3 root_position_m = Vec3::Zero();  ///< [m] root link frame in Ground at t = 0
    Vec3 root_rpy_rad = Vec3::Zero();     ///< [rad] roll, pitch, yaw (URDF convention)
    std::vector<UrdfCoupledLink> coupled; ///< in the order of wrenches and states
    std::vector<UrdfJointSettings> joints;
    IntegratorSettings integrator;
};

/// Reads the YAML (strict: unknown key, wrong unit or missing value name the key and line).
/// Joint and link names are checked against the URDF when the model is built; the errors then
/// name the YAML file, the key and its line.
UrdfModelSettings parseUrdfModel(const std::string &yaml_path);

class UrdfModel final : public SimbodyModel {
public:
    explicit UrdfModel(const UrdfModelSettings &settings);
    ~UrdfModel() override;

    /// Every joint's coordinates and speeds, each drive's effort (docs/user-models.md).
    std::map<std::string, double> observables() const override;

    /// Changes a joint's drive between windows (a procedure locking then driving a wheel).
    /// A speed drive or a lock also sets the joint's speed to the imposed one.
    void setDrive(const std::string &joint, const JointDrive &drive);
    JointDrive drive(const std::string &joint) const;
    const UrdfModelSettings &settings() const { return settings_; }
    /// Names of the URDF's joints in the order Simbody's tree holds them.
    std::vector<std::string> jointNames() const;

protected:
    std::string checkpointExtras() const override;
    void readCheckpointExtras(const std::string &line) override;

private:
    struct Joint;
    Joint &jointNamed(const std::string &name);
    const Joint &jointNamed(const std::string &name) const;
    void applyDrive(Joint &joint);

    UrdfModelSettings settings_;
    std::vector<Joint> joints_;
};

} // namespace grainlink::mbs
