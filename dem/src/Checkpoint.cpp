#include "grainlink/dem/Checkpoint.hpp"

#include "grainlink/config/Checksum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <type_traits>

namespace grainlink::dem {

namespace {

// Version 2 adds the contact pass's thread split, version 3 the neighbour skin in use and the
// bodies' and planes' loads, version 4 a checksum of everything between the magic and the
// trailer; versions 1 to 3 are still read.
constexpr char kMagic[8] = {'G', 'L', 'D', 'E', 'M', 'C', 'K', '4'};
constexpr char kMagicVersion3[8] = {'G', 'L', 'D', 'E', 'M', 'C', 'K', '3'};
constexpr char kMagicVersion2[8] = {'G', 'L', 'D', 'E', 'M', 'C', 'K', '2'};
constexpr char kMagicVersion1[8] = {'G', 'L', 'D', 'E', 'M', 'C', 'K', '1'};

using config::Checksum;

class Writer {
public:
    explicit Writer(std::ofstream &out) : out_(out) {}
    template <class T> void pod(const T &value) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(reinterpret_cast<const char *>(&value), sizeof(T));
    }
    void bytes(const char *data, std::size_t n) {
        out_.write(data, std::streamsize(n));
        checksum_.add(data, n);
    }
    std::uint64_t checksum() const { return checksum_.value; }
    template <class T> void vec(const std::vector<T> &values) {
        pod<std::uint64_t>(values.size());
        for (const T &v : values)
            item(v);
    }
    void item(const Vec3 &v) { pod(v.x()), pod(v.y()), pod(v.z()); }
    void item(const Quat &q) { pod(q.w()), pod(q.x()), pod(q.y()), pod(q.z()); }
    void item(const ContactHistory &h) {
        item(h.tangential_m);
        item(h.rolling_N_m);
        pod<std::uint8_t>(h.sliding);
    }
    void item(const RigidBodyState &s) {
        item(s.position_m);
        item(s.orientation);
        item(s.linear_velocity_m_s);
        item(s.angular_velocity_rad_s);
    }
    void item(const MeshContactSlot &s) {
        pod<std::int32_t>(s.body);
        pod<std::int32_t>(s.triangle);
        item(s.normal);
        item(s.history);
    }
    void item(const NeighbourList::StoredContact &c) {
        pod<std::uint64_t>(c.i);
        pod<std::uint64_t>(c.j);
        item(c.history);
    }
    void item(const BodyLoads &l) {
        item(l.force_N);
        item(l.torque_N_m);
        item(l.impulse_N_s);
        item(l.angular_impulse_N_m_s);
        pod(l.accumulated_time_s);
    }
    template <class T> std::enable_if_t<std::is_arithmetic_v<T>> item(const T &v) { pod(v); }
    void text(const std::string &s) {
        pod<std::uint64_t>(s.size());
        bytes(s.data(), s.size());
    }

private:
    std::ofstream &out_;
    Checksum checksum_;
};

class Reader {
public:
    /// Reads from where `in` stands (after the magic).
    Reader(std::ifstream &in, std::string path) : in_(in), path_(std::move(path)) {
        const std::streampos here = in_.tellg();
        in_.seekg(0, std::ios::end);
        size_ = std::uint64_t(std::max<std::streamoff>(0, in_.tellg()));
        in_.seekg(here);
    }
    template <class T> T pod() {
        T value;
        in_.read(reinterpret_cast<char *>(&value), sizeof(T));
        if (!in_)
            throw std::runtime_error("checkpoint '" + path_ + "' is truncated");
        return value;
    }
    template <class T> void vec(std::vector<T> &values) {
        const auto n = pod<std::uint64_t>();
        // Every item takes at least a byte: a count beyond the bytes left is a damaged file,
        // refused before it allocates (a flipped bit asked for 2^43 bytes).
        const auto at = std::uint64_t(std::max<std::streamoff>(0, in_.tellg()));
        if (n > size_ - std::min(size_, at))
            throw std::runtime_error("checkpoint '" + path_ + "' is corrupt (a count of " +
                                     std::to_string(n) + " beyond the file's end)");
        values.resize(n);
        for (T &v : values)
            item(v);
    }
    void item(Vec3 &v) { v.x() = pod<double>(), v.y() = pod<double>(), v.z() = pod<double>(); }
    void item(Quat &q) {
        q.w() = pod<double>(), q.x() = pod<double>(), q.y() = pod<double>(), q.z() = pod<double>();
    }
    void item(ContactHistory &h) {
        item(h.tangential_m);
        item(h.rolling_N_m);
        h.sliding = pod<std::uint8_t>() != 0;
    }
    void item(RigidBodyState &s) {
        item(s.position_m);
        item(s.orientation);
        item(s.linear_velocity_m_s);
        item(s.angular_velocity_rad_s);
    }
    void item(MeshContactSlot &s) {
        s.body = pod<std::int32_t>();
        s.triangle = pod<std::int32_t>();
        item(s.normal);
        item(s.history);
    }
    void item(NeighbourList::StoredContact &c) {
        c.i = pod<std::uint64_t>();
        c.j = pod<std::uint64_t>();
        item(c.history);
    }
    void item(BodyLoads &l) {
        item(l.force_N);
        item(l.torque_N_m);
        item(l.impulse_N_s);
        item(l.angular_impulse_N_m_s);
        l.accumulated_time_s = pod<double>();
    }
    template <class T> std::enable_if_t<std::is_arithmetic_v<T>> item(T &v) { v = pod<T>(); }
    std::string text() {
        const auto n = pod<std::uint64_t>();
        if (n > 4096)
            throw std::runtime_error("checkpoint '" + path_ + "' is corrupt");
        std::string s(n, '\0');
        in_.read(s.data(), std::streamsize(n));
        return s;
    }

private:
    std::ifstream &in_;
    std::string path_;
    std::uint64_t size_ = 0; ///< [bytes] of the file
};

} // namespace

void writeCheckpoint(const DemSystem &system, const std::string &path,
                     const CheckpointExtras &extras) {
    const std::string temporary = path + ".partial";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out)
            throw std::runtime_error("cannot write checkpoint '" + temporary + "'");
        Writer w(out);
        out.write(kMagic, sizeof kMagic);
        const ParticleStore &p = system.particles();
        w.pod<std::uint64_t>(p.nextId());
        w.vec(p.id);
        w.vec(p.position);
        w.vec(p.velocity);
        w.vec(p.angular_velocity);
        w.vec(p.orientation);
        w.vec(p.force);
        w.vec(p.torque);
        w.vec(p.radius);
        w.vec(p.mass);
        w.vec(p.inertia);
        w.vec(p.material);
        const DemSystem::Internals s = system.saveInternals();
        w.pod(s.step);
        w.vec(s.contacts);
        w.vec(s.plane_history);
        w.vec(s.mesh_slots);
        w.vec(s.reference_position);
        w.vec(s.mesh_reference_position);
        w.vec(s.body_states);
        w.vec(s.body_reference);
        w.pod(s.neighbour_builds);
        w.pod<std::uint8_t>(s.forces_valid);
        w.pod(s.step_offset);
        w.pod(s.time_offset_s);
        w.pod(s.max_overlap_ratio);
        w.vec(s.contact_split);
        w.pod(s.skin_m);
        w.vec(s.body_loads);
        w.vec(s.plane_force);
        w.pod<std::uint64_t>(extras.size());
        for (const auto &[key, value] : extras) {
            w.text(key);
            w.pod(value);
        }
        const std::uint64_t checksum = w.checksum();
        out.write(reinterpret_cast<const char *>(&checksum), sizeof checksum);
        out.write(kMagic, sizeof kMagic); // trailer: proves the file is complete
        if (!out)
            throw std::runtime_error("failed writing checkpoint '" + temporary + "'");
    }
    if (std::rename(temporary.c_str(), path.c_str()) != 0)
        throw std::runtime_error("cannot move checkpoint into place at '" + path + "'");
}

namespace {

// Every number a checkpoint holds must be finite: a NaN body position or skin reached the
// neighbour grid's cell index (undefined behaviour) before it reached any check.
bool finite(const Vec3 &v) { return v.allFinite(); }
bool finite(const ContactHistory &h) { return finite(h.tangential_m) && finite(h.rolling_N_m); }
bool finite(const MeshContactSlot &m) { return finite(m.normal) && finite(m.history); }
bool finite(const NeighbourList::StoredContact &c) { return finite(c.history); }
bool finite(const RigidBodyState &b) {
    return finite(b.position_m) && finite(b.linear_velocity_m_s) &&
           finite(b.angular_velocity_rad_s) && b.orientation.coeffs().allFinite() &&
           std::abs(b.orientation.norm() - 1.0) < 1e-3;
}
bool finite(const BodyLoads &l) {
    return finite(l.force_N) && finite(l.torque_N_m) && finite(l.impulse_N_s) &&
           finite(l.angular_impulse_N_m_s) && std::isfinite(l.accumulated_time_s);
}
template <class T> void requireFinite(const std::vector<T> &items, const char *what,
                                      const std::string &path) {
    for (const T &item : items)
        if (!finite(item))
            throw std::runtime_error("checkpoint '" + path + "' is corrupt: a non-finite " + what);
}

/// Version 4: the checksum of everything between the magic and the stored checksum must match
/// before a byte of it is believed. Leaves `in` where it was (after the magic).
void verifyChecksum(std::ifstream &in, const std::string &path) {
    const std::streampos start = in.tellg();
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    const std::streamoff body = size - std::streamoff(start) - 16; // checksum + trailer
    if (body < 0)
        throw std::runtime_error("checkpoint '" + path + "' is truncated");
    // A cut file has lost its trailer: say so, rather than that its checksum differs.
    char trailer[8];
    in.seekg(size - 8);
    in.read(trailer, sizeof trailer);
    if (!in || std::memcmp(trailer, kMagic, sizeof trailer) != 0)
        throw std::runtime_error("checkpoint '" + path + "' is truncated (no trailer)");
    in.seekg(start);
    Checksum sum;
    std::vector<char> buffer(1 << 16);
    for (std::streamoff left = body; left > 0;) {
        const auto n = std::streamsize(std::min<std::streamoff>(left, std::streamoff(buffer.size())));
        in.read(buffer.data(), n);
        if (!in)
            throw std::runtime_error("checkpoint '" + path + "' is truncated");
        sum.add(buffer.data(), std::size_t(n));
        left -= n;
    }
    std::uint64_t stored = 0;
    in.read(reinterpret_cast<char *>(&stored), sizeof stored);
    if (!in || stored != sum.value)
        throw std::runtime_error("checkpoint '" + path +
                                 "' is damaged: its checksum does not match its contents");
    in.seekg(start);
}

CheckpointExtras load(const std::string &path, ParticleStore &p, DemSystem::Internals &s) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw std::runtime_error("cannot open checkpoint '" + path + "'");
    char magic[8];
    in.read(magic, sizeof magic);
    int version = 0;
    for (const auto &[known, number] :
         {std::pair{kMagicVersion1, 1}, std::pair{kMagicVersion2, 2},
          std::pair{kMagicVersion3, 3}, std::pair{kMagic, 4}})
        if (in && std::memcmp(magic, known, sizeof magic) == 0)
            version = number;
    if (version == 0)
        throw std::runtime_error("'" + path +
                                 "' is not a grainlink DEM checkpoint (version 1 to 4)");
    if (version >= 4)
        verifyChecksum(in, path);
    const std::string trailer(magic, sizeof magic);
    Reader r(in, path);
    p.setNextId(r.pod<std::uint64_t>());
    r.vec(p.id);
    r.vec(p.position);
    r.vec(p.velocity);
    r.vec(p.angular_velocity);
    r.vec(p.orientation);
    r.vec(p.force);
    r.vec(p.torque);
    r.vec(p.radius);
    r.vec(p.mass);
    r.vec(p.inertia);
    r.vec(p.material);
    p.inv_mass.resize(p.mass.size());
    for (std::size_t i = 0; i < p.mass.size(); ++i)
        p.inv_mass[i] = 1.0 / p.mass[i];
    const std::size_t n = p.id.size();
    for (std::size_t size : {p.position.size(), p.velocity.size(), p.angular_velocity.size(),
                             p.orientation.size(), p.force.size(), p.torque.size(),
                             p.radius.size(), p.mass.size(), p.inertia.size(), p.material.size()})
        if (size != n)
            throw std::runtime_error("checkpoint '" + path + "' has inconsistent particle arrays");
    // A damaged state would reach the neighbour grid and the stability estimate as NaN or a
    // radius of 1e-300: refused here, naming the grain.
    for (std::size_t i = 0; i < n; ++i) {
        const bool sound = p.position[i].allFinite() && p.velocity[i].allFinite() &&
                           p.angular_velocity[i].allFinite() &&
                           std::abs(p.orientation[i].norm() - 1.0) < 1e-3 &&
                           std::isfinite(p.radius[i]) && p.radius[i] > 1e-9 &&
                           std::isfinite(p.mass[i]) && p.mass[i] > 0.0 &&
                           p.inertia[i].allFinite() && (p.inertia[i].array() > 0.0).all();
        if (!sound)
            throw std::runtime_error("checkpoint '" + path + "' is corrupt: grain " +
                                     std::to_string(p.id[i]) + " has a non-finite or impossible "
                                     "position, velocity, orientation, radius, mass or inertia");
    }
    s.step = r.pod<std::uint64_t>();
    r.vec(s.contacts);
    r.vec(s.plane_history);
    r.vec(s.mesh_slots);
    r.vec(s.reference_position);
    r.vec(s.mesh_reference_position);
    r.vec(s.body_states);
    r.vec(s.body_reference);
    s.neighbour_builds = r.pod<std::uint64_t>();
    s.forces_valid = r.pod<std::uint8_t>() != 0;
    s.step_offset = r.pod<std::uint64_t>();
    s.time_offset_s = r.pod<double>();
    s.max_overlap_ratio = r.pod<double>();
    if (version >= 2)
        r.vec(s.contact_split);
    if (version >= 3) {
        s.skin_m = r.pod<double>();
        r.vec(s.body_loads);
        r.vec(s.plane_force);
    }
    CheckpointExtras extras;
    const auto count = r.pod<std::uint64_t>();
    for (std::uint64_t k = 0; k < count; ++k) {
        std::string key = r.text();
        extras[key] = r.pod<double>();
    }
    if (version >= 4)
        r.pod<std::uint64_t>(); // the checksum, verified before anything was read
    in.read(magic, sizeof magic);
    if (!in || std::memcmp(magic, trailer.data(), sizeof magic) != 0)
        throw std::runtime_error("checkpoint '" + path + "' is truncated (no trailer)");
    for (const auto &c : s.contacts)
        if (c.i >= n || c.j >= n)
            throw std::runtime_error("checkpoint '" + path +
                                     "' has a contact beyond the particles");
    requireFinite(s.contacts, "contact history", path);
    requireFinite(s.plane_history, "wall contact history", path);
    requireFinite(s.mesh_slots, "mesh contact", path);
    requireFinite(s.reference_position, "neighbour reference position", path);
    requireFinite(s.mesh_reference_position, "mesh reference position", path);
    requireFinite(s.body_states, "body state (or a non-unit orientation)", path);
    requireFinite(s.body_reference, "body reference state", path);
    requireFinite(s.body_loads, "body load", path);
    requireFinite(s.plane_force, "wall force", path);
    // The clock offset, the neighbour skin and the deepest overlap seen so far.
    for (double x : {s.time_offset_s, s.skin_m, s.max_overlap_ratio})
        if (!std::isfinite(x) || x < 0.0)
            throw std::runtime_error("checkpoint '" + path +
                                     "' is corrupt: a clock, skin or overlap of " +
                                     std::to_string(x));
    return extras;
}

} // namespace

CheckpointExtras readCheckpoint(DemSystem &system, const std::string &path) {
    ParticleStore particles;
    DemSystem::Internals internals;
    CheckpointExtras extras = load(path, particles, internals);
    for (int m : particles.material)
        if (m < 0 || std::size_t(m) >= system.materials().size())
            throw std::runtime_error("'" + path + "': checkpoint has grains of material " +
                                     std::to_string(m) + ", the scenario defines " +
                                     std::to_string(system.materials().size()) +
                                     " (a checkpoint of another scenario?)");
    system.particles() = std::move(particles);
    try {
        system.restoreInternals(internals);
    } catch (const std::runtime_error &e) {
        throw std::runtime_error("'" + path + "': " + e.what() +
                                 " (a checkpoint of another scenario?)");
    }
    return extras;
}

CheckpointExtras readCheckpointExtras(const std::string &path) {
    ParticleStore particles;
    DemSystem::Internals internals;
    return load(path, particles, internals);
}

} // namespace grainlink::dem
