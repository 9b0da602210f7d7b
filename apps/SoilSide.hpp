#pragma once
// What the soil-side participants (the DEM soil, the rigid floor) share: the mesh of a coupled
// body from its handshake description, and the body's motion through a window as the DEM's
// dem::WindowMotion (position and velocity agree with the received states at both ends).
#include "Nodes.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/coupling/Types.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/dem/Walls.hpp"
#include "grainlink/dem/WheelMesh.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace grainlink::apps {

/// A soil-side participant of the scenario `root` consuming the node's `--bodies`.
inline coupling::ParticipantConfig soilParticipantConfig(const NodeOptions &options,
                                                         const config::ConfigNode &root) {
    coupling::ParticipantConfig config;
    config.name = options.name;
    config.handshake_timeout_s = handshakeTimeout(root);
    config.role = coupling::Role::Soil;
    config.endpoint = options.endpoint;
    config.consumes = options.bodies;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    return config;
}

/// The bed of a soil node: a DEM scenario (section `section`) without what the coupling decides:
/// its duration, its bodies, its rows and checkpoints. A key for those would change nothing.
inline dem::DemScenario parseSoilSection(const config::ConfigNode &root,
                                         const std::string &section) {
    const config::ConfigNode soil = root[section];
    if (soil.has("name"))
        soil["name"].fail("a soil node's files are named after its section (--section), not "
                          "`name`: remove the key");
    if (soil.has("run"))
        soil["run"].fail("a coupled soil runs as long as the coordinator says (coupling."
                         "end_time_s): remove the key");
    if (soil.has("bodies"))
        soil["bodies"].fail("a coupled soil's bodies come from the multibody participant (the "
                            "soil node's --bodies): remove the key");
    if (const auto out = soil.optional("output"))
        for (const char *key : {"series_interval_s", "checkpoint_interval_s"})
            if (out->has(key))
                (*out)[key].fail("the soil node writes a row every window and a checkpoint "
                                 "when the coordinator asks (coupling.checkpoint_every_windows): "
                                 "remove the key");
    return dem::parseScenario(soil, true);
}

/// The description of the consumed body `name` among the run's bodies.
inline const coupling::BodyDescription &describedBody(const coupling::RunInfo &run,
                                                      const std::string &name) {
    for (const auto &body : run.bodies)
        if (body.name == name)
            return body;
    throw coupling::CouplingError("the run has no body '" + name + "' (check --bodies)");
}

/// The triangle mesh the grains touch, built from the body's description exactly as its
/// provider gave it (a parametric wheel, or a mesh).
inline dem::TriangleMesh meshOf(const coupling::BodyDescription &body, bool half = false) {
    if (const auto *wheel = std::get_if<coupling::WheelShape>(&body.geometry)) {
        dem::WheelMeshOptions options;
        options.half = half;
        try {
            return dem::makeWheel(*wheel, options);
        } catch (const std::invalid_argument &e) {
            throw coupling::CouplingError("body '" + body.name + "': " + e.what());
        }
    }
    if (half)
        throw coupling::CouplingError("body '" + body.name + "': a mirror-symmetric half model "
                                      "needs parametric wheels, not a mesh");
    if (const auto *m = std::get_if<coupling::MeshShape>(&body.geometry)) {
        dem::TriangleMesh mesh;
        mesh.vertices_m = m->vertices_m;
        mesh.triangles = m->triangles;
        return mesh;
    }
    throw coupling::CouplingError("body '" + body.name + "' has no geometry the soil can touch");
}

/// A coupled body's state as the DEM's rigid-body state.
inline dem::RigidBodyState demState(const coupling::BodyState &s) {
    dem::RigidBodyState r;
    r.position_m = s.position_m;
    r.orientation = s.orientation;
    r.linear_velocity_m_s = s.linear_velocity_m_s;
    r.angular_velocity_rad_s = s.angular_velocity_rad_s;
    return r;
}

/// Body b's motion through the window `in` (dem::WindowMotion, docs/physics.md §7.2), on a
/// clock `offset_s` ahead of the coupling's.
inline dem::WindowMotion windowMotion(const coupling::WindowInputs &in, std::size_t b,
                                      double offset_s = 0.0) {
    return {in.start_s + offset_s, in.duration_s, demState(in.start_states.at(b)),
            demState(in.end_states.at(b))};
}

/// Mirror symmetry (DIGEST §5): the soil simulates only the half of the bin at y >= plane, with
/// a frictionless wall on the plane, and each wheel's y >= 0 half; the other half is the mirror
/// image. The image's wrench about a body origin on the plane is (Fx, -Fy, Fz), (-Tx, Ty, -Tz),
/// so the full wheel's wrench is twice the half's x and z force and y torque, the rest zero.
struct MirrorSymmetry {
    double plane_y_m = 0.0;

    static std::optional<MirrorSymmetry> parse(const config::ConfigNode &root) {
        const auto node = root.optional("mirror");
        if (!node)
            return std::nullopt;
        MirrorSymmetry m;
        m.plane_y_m = (*node)["plane_y_m"].number();
        node->finish();
        return m;
    }
    /// A wheel must roll in the plane: centre on it, axis across it.
    void check(const coupling::BodyState &s) const {
        const coupling::Vec3 axis = s.orientation * coupling::Vec3::UnitY();
        if (std::abs(s.position_m.y() - plane_y_m) > 1e-9 || std::abs(axis.y()) < 1.0 - 1e-9)
            throw coupling::CouplingError(
                "body '" + s.body + "' is not on the mirror plane y = " + std::to_string(plane_y_m) +
                " m with its axis across it (centre at y = " + std::to_string(s.position_m.y()) +
                " m): start it there or remove `mirror:`");
    }
    static void complete(coupling::Vec3 &force, coupling::Vec3 &torque) {
        force = coupling::Vec3(2.0 * force.x(), 0.0, 2.0 * force.z());
        torque = coupling::Vec3(0.0, 2.0 * torque.y(), 0.0);
    }
};

} // namespace grainlink::apps
