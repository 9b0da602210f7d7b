#include "Codec.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace grainlink::coupling::codec {

void toWire(const Vec3 &v, pb::Vec3 *out) {
    out->set_x(v.x());
    out->set_y(v.y());
    out->set_z(v.z());
}

Vec3 fromWire(const pb::Vec3 &v) {
    return Vec3(v.x(), v.y(), v.z());
}

void toWire(const BodyDescription &body, pb::BodyDescription *out) {
    out->set_name(body.name);
    auto *mass = out->mutable_mass();
    mass->set_mass_kg(body.mass.mass_kg);
    toWire(body.mass.center_of_mass_m, mass->mutable_center_of_mass_m());
    toWire(body.mass.inertia_diagonal_kg_m2, mass->mutable_inertia_diagonal_kg_m2());
    toWire(body.mass.inertia_off_diagonal_kg_m2, mass->mutable_inertia_off_diagonal_kg_m2());
    if (const auto *mesh = std::get_if<MeshShape>(&body.geometry)) {
        auto *m = out->mutable_mesh();
        for (const auto &v : mesh->vertices_m)
            toWire(v, m->add_vertices_m());
        for (const auto &t : mesh->triangles)
            for (int i : t)
                m->add_triangle_indices(std::uint32_t(i));
    } else if (const auto *wheel = std::get_if<WheelShape>(&body.geometry)) {
        auto *w = out->mutable_wheel();
        w->set_diameter_m(wheel->diameter_m);
        w->set_width_m(wheel->width_m);
        w->set_rim_thickness_m(wheel->rim_thickness_m);
        w->set_grouser_count(wheel->grouser_count);
        w->set_grouser_height_m(wheel->grouser_height_m);
        w->set_grouser_thickness_m(wheel->grouser_thickness_m);
        w->set_grouser_shape(wheel->grouser_shape == GrouserShape::Chevron
                                 ? pb::GROUSER_SHAPE_CHEVRON
                                 : pb::GROUSER_SHAPE_STRAIGHT);
        w->set_chevron_angle_deg(wheel->chevron_angle_deg);
        w->set_closed_sides(wheel->closed_sides);
    }
}

namespace {

/// Throws the protocol error for body `name` unless `ok`.
void require(bool ok, const std::string &name, const std::string &what) {
    if (!ok)
        throw ProtocolError(pb::Error::CODE_MALFORMED, "body '" + printable(name) + "': " + what);
}

bool finite(const Vec3 &v) { return v.allFinite(); }

} // namespace

BodyDescription fromWire(const pb::BodyDescription &body) {
    BodyDescription out;
    out.name = body.name();
    out.mass.mass_kg = body.mass().mass_kg();
    out.mass.center_of_mass_m = fromWire(body.mass().center_of_mass_m());
    out.mass.inertia_diagonal_kg_m2 = fromWire(body.mass().inertia_diagonal_kg_m2());
    out.mass.inertia_off_diagonal_kg_m2 = fromWire(body.mass().inertia_off_diagonal_kg_m2());
    // Numbers that would reach the soil's mesh and integrator: finite, and sizes in range.
    require(std::isfinite(out.mass.mass_kg) && out.mass.mass_kg >= 0.0, body.name(),
            "mass_kg must be finite and not negative");
    require(finite(out.mass.center_of_mass_m) && finite(out.mass.inertia_diagonal_kg_m2) &&
                finite(out.mass.inertia_off_diagonal_kg_m2),
            body.name(), "non-finite centre of mass or inertia");
    if (body.has_mesh()) {
        const auto &indices = body.mesh().triangle_indices();
        MeshShape mesh;
        for (const auto &v : body.mesh().vertices_m()) {
            mesh.vertices_m.push_back(fromWire(v));
            require(finite(mesh.vertices_m.back()), body.name(), "non-finite mesh vertex");
        }
        if (indices.size() % 3 != 0)
            throw ProtocolError(pb::Error::CODE_MALFORMED,
                                "body '" + printable(body.name()) + "': triangle index count " +
                                    std::to_string(indices.size()) + " is not a multiple of 3");
        for (auto i : indices)
            if (i >= mesh.vertices_m.size())
                throw ProtocolError(pb::Error::CODE_MALFORMED,
                                    "body '" + printable(body.name()) + "': triangle index " +
                                        std::to_string(i) + " beyond " +
                                        std::to_string(mesh.vertices_m.size()) + " vertices");
        for (int t = 0; t + 2 < indices.size(); t += 3)
            mesh.triangles.push_back({int(indices[t]), int(indices[t + 1]), int(indices[t + 2])});
        out.geometry = std::move(mesh);
    } else if (body.has_wheel()) {
        const auto &w = body.wheel();
        WheelShape wheel;
        wheel.diameter_m = w.diameter_m();
        wheel.width_m = w.width_m();
        wheel.rim_thickness_m = w.rim_thickness_m();
        wheel.grouser_count = w.grouser_count();
        wheel.grouser_height_m = w.grouser_height_m();
        wheel.grouser_thickness_m = w.grouser_thickness_m();
        wheel.grouser_shape = w.grouser_shape() == pb::GROUSER_SHAPE_CHEVRON
                                  ? GrouserShape::Chevron
                                  : GrouserShape::Straight;
        wheel.chevron_angle_deg = w.chevron_angle_deg();
        wheel.closed_sides = w.closed_sides();
        const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
        const auto size = [](double x) { return std::isfinite(x) && x >= 0.0; };
        require(positive(wheel.diameter_m) && positive(wheel.width_m), body.name(),
                "wheel diameter_m and width_m must be finite and positive");
        require(size(wheel.rim_thickness_m) && wheel.rim_thickness_m < 0.5 * wheel.diameter_m,
                body.name(), "wheel rim_thickness_m must lie in [0, the rim radius)");
        require(wheel.grouser_count <= unsigned(body::kMaxGrousers), body.name(),
                "wheel grouser_count " + std::to_string(wheel.grouser_count) + " above " +
                    std::to_string(body::kMaxGrousers));
        require(size(wheel.grouser_height_m) && size(wheel.grouser_thickness_m) &&
                    std::isfinite(wheel.chevron_angle_deg) &&
                    std::abs(wheel.chevron_angle_deg) < 80.0,
                body.name(), "wheel grouser sizes must be finite and not negative, the chevron "
                             "angle within (-80, 80) deg");
        out.geometry = wheel;
    }
    return out;
}

void toWire(const BodyState &state, pb::BodyState *out) {
    out->set_body(state.body);
    toWire(state.position_m, out->mutable_position_m());
    auto *q = out->mutable_orientation();
    q->set_w(state.orientation.w());
    q->set_x(state.orientation.x());
    q->set_y(state.orientation.y());
    q->set_z(state.orientation.z());
    toWire(state.linear_velocity_m_s, out->mutable_linear_velocity_m_s());
    toWire(state.angular_velocity_rad_s, out->mutable_angular_velocity_rad_s());
    out->set_frame(pb::FRAME_WORLD);
}

BodyState fromWire(const pb::BodyState &state) {
    if (state.frame() != pb::FRAME_WORLD)
        throw ProtocolError(pb::Error::CODE_MALFORMED, "state of body '" + printable(state.body()) +
                                                           "' is not in the world frame");
    if (!state.has_orientation())
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "state of body '" + printable(state.body()) + "' has no orientation");
    BodyState out;
    out.body = state.body();
    out.position_m = fromWire(state.position_m());
    const auto &q = state.orientation();
    out.orientation = Quat(q.w(), q.x(), q.y(), q.z());
    const double norm = out.orientation.norm();
    if (!(std::abs(norm - 1.0) < 1e-6))
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "orientation of body '" + printable(state.body()) +
                                "' is not a unit quaternion (|q| = " + std::to_string(norm) + ")");
    out.linear_velocity_m_s = fromWire(state.linear_velocity_m_s());
    out.angular_velocity_rad_s = fromWire(state.angular_velocity_rad_s());
    return out;
}

void toWire(const std::vector<BodyState> &states, Ticks tick, pb::BodyStates *out) {
    out->set_tick(tick);
    for (const auto &s : states)
        toWire(s, out->add_states());
}

void toWire(const std::vector<BodyState> &states, const std::vector<std::size_t> &which, Ticks tick,
            pb::BodyStates *out) {
    out->set_tick(tick);
    out->mutable_states()->Reserve(static_cast<int>(which.size()));
    for (const auto b : which)
        toWire(states[b], out->add_states());
}

std::vector<BodyState> fromWire(const pb::BodyStates &states) {
    std::vector<BodyState> out;
    fromWire(states, out);
    return out;
}

void fromWire(const pb::BodyStates &states, std::vector<BodyState> &out) {
    out.resize(static_cast<std::size_t>(states.states_size()));
    for (int i = 0; i < states.states_size(); ++i)
        out[static_cast<std::size_t>(i)] = fromWire(states.states(i));
}

void toWire(const Wrench &wrench, pb::BodyWrench *out) {
    out->set_body(wrench.body);
    toWire(wrench.force_N, out->mutable_force_n());
    toWire(wrench.torque_N_m, out->mutable_torque_n_m());
    for (const auto &f : wrench.triangle_forces_N)
        toWire(f, out->add_triangle_forces_n());
    out->set_frame(pb::FRAME_WORLD);
}

Wrench fromWire(const pb::BodyWrench &wrench) {
    if (wrench.frame() != pb::FRAME_WORLD)
        throw ProtocolError(pb::Error::CODE_MALFORMED, "wrench on body '" +
                                                           printable(wrench.body()) +
                                                           "' is not in the world frame");
    Wrench out;
    out.body = wrench.body();
    out.force_N = fromWire(wrench.force_n());
    out.torque_N_m = fromWire(wrench.torque_n_m());
    for (const auto &f : wrench.triangle_forces_n())
        out.triangle_forces_N.push_back(fromWire(f));
    return out;
}

void toWire(const std::vector<Wrench> &wrenches, Ticks start, Ticks end, pb::BodyWrenches *out) {
    out->set_start_tick(start);
    out->set_end_tick(end);
    for (const auto &w : wrenches)
        toWire(w, out->add_wrenches());
}

void toWire(const std::vector<Wrench> &wrenches, const std::vector<std::size_t> &which, Ticks start,
            Ticks end, pb::BodyWrenches *out) {
    out->set_start_tick(start);
    out->set_end_tick(end);
    out->mutable_wrenches()->Reserve(static_cast<int>(which.size()));
    for (const auto b : which)
        toWire(wrenches[b], out->add_wrenches());
}

std::vector<Wrench> fromWire(const pb::BodyWrenches &wrenches) {
    std::vector<Wrench> out;
    fromWire(wrenches, out);
    return out;
}

void fromWire(const pb::BodyWrenches &wrenches, std::vector<Wrench> &out) {
    out.resize(static_cast<std::size_t>(wrenches.wrenches_size()));
    for (int i = 0; i < wrenches.wrenches_size(); ++i)
        out[static_cast<std::size_t>(i)] = fromWire(wrenches.wrenches(i));
}

pb::Role toWire(Role role) {
    return role == Role::Multibody ? pb::ROLE_MULTIBODY : pb::ROLE_SOIL;
}

Role fromWire(pb::Role role, const std::string &who) {
    switch (role) {
    case pb::ROLE_MULTIBODY:
        return Role::Multibody;
    case pb::ROLE_SOIL:
        return Role::Soil;
    default:
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            who + ": Hello has no role (expected multibody or soil)");
    }
}

pb::Scheme toWire(SchemeKind scheme) {
    switch (scheme) {
    case SchemeKind::ExplicitSerial:
        return pb::SCHEME_EXPLICIT_SERIAL;
    case SchemeKind::ExplicitParallel:
        return pb::SCHEME_EXPLICIT_PARALLEL;
    case SchemeKind::Implicit:
        return pb::SCHEME_IMPLICIT;
    }
    return pb::SCHEME_UNSPECIFIED;
}

SchemeKind fromWire(pb::Scheme scheme) {
    switch (scheme) {
    case pb::SCHEME_EXPLICIT_SERIAL:
        return SchemeKind::ExplicitSerial;
    case pb::SCHEME_EXPLICIT_PARALLEL:
        return SchemeKind::ExplicitParallel;
    case pb::SCHEME_IMPLICIT:
        return SchemeKind::Implicit;
    default:
        throw ProtocolError(pb::Error::CODE_MALFORMED, "Welcome names no coupling scheme");
    }
}

std::string encode(const pb::Envelope &envelope) {
    std::string bytes;
    envelope.SerializeToString(&bytes);
    return bytes;
}

namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::io::CodedInputStream;
using Wire = google::protobuf::internal::WireFormatLite;

/// Walks the bytes as `type` without building it, counting the sub-messages and strings parsing
/// would make; false once more than `budget` are left. Malformed bytes end the walk with true:
/// the parser that follows names them. The schema has no recursive types, so neither has this.
bool withinParts(const Descriptor *type, CodedInputStream &in, std::size_t &budget) {
    for (std::uint32_t tag = in.ReadTag(); tag != 0; tag = in.ReadTag()) {
        if (Wire::GetTagWireType(tag) != Wire::WIRETYPE_LENGTH_DELIMITED) {
            if (!Wire::SkipField(&in, tag))
                return true;
            continue;
        }
        std::uint32_t length = 0;
        if (!in.ReadVarint32(&length))
            return true;
        const FieldDescriptor *field = type->FindFieldByNumber(Wire::GetTagFieldNumber(tag));
        const bool message = field && field->type() == FieldDescriptor::TYPE_MESSAGE;
        const bool text = field && (field->type() == FieldDescriptor::TYPE_STRING ||
                                    field->type() == FieldDescriptor::TYPE_BYTES);
        if ((message || text) && budget-- == 0)
            return false;
        if (!message) {
            if (!in.Skip(static_cast<int>(length)))
                return true;
            continue;
        }
        const auto limit = in.PushLimit(static_cast<int>(length));
        if (!withinParts(field->message_type(), in, budget))
            return false;
        in.PopLimit(limit);
    }
    return true;
}

} // namespace

pb::Envelope decode(const void *data, std::size_t size, const std::string &from,
                    std::size_t max_parts) {
    pb::Envelope envelope;
    decode(data, size, from, envelope, max_parts);
    return envelope;
}

void decode(const void *data, std::size_t size, const std::string &from, pb::Envelope &envelope,
            std::size_t max_parts) {
    if (max_parts != SIZE_MAX) {
        CodedInputStream in(static_cast<const std::uint8_t *>(data), static_cast<int>(size));
        std::size_t budget = max_parts;
        if (!withinParts(pb::Envelope::descriptor(), in, budget))
            throw ProtocolError(pb::Error::CODE_MALFORMED,
                                "message from " + from + " (" + std::to_string(size) +
                                    " bytes) would unpack into more than " +
                                    std::to_string(max_parts) +
                                    " sub-messages and strings (limits.max_message_bytes / 16)");
    }
    if (!envelope.ParseFromArray(data, static_cast<int>(size)))
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "malformed message from " + from + " (" + std::to_string(size) +
                                " bytes that are not a grainlink.v1.Envelope)");
    if (envelope.version() != kProtocolMajor)
        throw ProtocolError(pb::Error::CODE_VERSION_MISMATCH,
                            from + " speaks protocol major version " +
                                std::to_string(envelope.version()) + ", this side speaks " +
                                std::to_string(kProtocolMajor),
                            envelope.sender(), envelope.version());
    if (envelope.body_case() == pb::Envelope::BODY_NOT_SET)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "message from " + from + " has no body (an unset body is an error)",
                            envelope.sender());
}

ScratchEnvelope::ScratchEnvelope()
    : block_(std::make_unique<char[]>(kBlockBytes)), arena_(block_.get(), kBlockBytes) {}

pb::Envelope &ScratchEnvelope::fresh() {
    arena_.Reset();
    return *google::protobuf::Arena::CreateMessage<pb::Envelope>(&arena_);
}

std::string bodyName(const pb::Envelope &envelope) {
    const auto *field = pb::Envelope::descriptor()->FindFieldByNumber(envelope.body_case());
    return field ? field->name() : "nothing";
}

std::string describe(const pb::Envelope &envelope) {
    return bodyName(envelope) + " for window " + std::to_string(envelope.window());
}

std::string printable(std::string_view text, std::size_t max_bytes) {
    const std::size_t shown = std::min(text.size(), max_bytes);
    std::string out;
    out.reserve(shown);
    for (std::size_t i = 0; i < shown; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7f && c != '\\') {
            out += static_cast<char>(c);
        } else {
            char escaped[5];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
            out += escaped;
        }
    }
    if (shown < text.size())
        out += "... (" + std::to_string(text.size()) + " bytes)";
    return out;
}

void checkHeader(const pb::Envelope &e, const std::string &name, std::uint64_t last_sequence) {
    if (e.sender() != name)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "sent a message signed '" + printable(e.sender()) + "'");
    if (e.sequence() <= last_sequence)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "sent message " + std::to_string(e.sequence()) + " again (duplicate; " +
                                "last was " + std::to_string(last_sequence) + ")");
    if (e.sequence() != last_sequence + 1)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "sent message " + std::to_string(e.sequence()) + " after " +
                                std::to_string(last_sequence) + " (out of order)");
}

} // namespace grainlink::coupling::codec
