#include "Admission.hpp"

#include <cstdio>

namespace grainlink::coupling {

namespace pb = codec::pb;
using codec::printable;
using codec::ProtocolError;

namespace {

void checkName(const std::string &name, const CoordinatorLimits &limits) {
    bool control = false;
    for (const unsigned char c : name)
        control = control || c < 0x20 || c == 0x7f;
    if (name.empty() || name.size() > limits.max_name_bytes || control)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "body name '" + printable(name) + "' is not 1 to " +
                                std::to_string(limits.max_name_bytes) +
                                " bytes without control characters (limits.max_name_bytes)");
}

void checkCount(const char *what, int count, const CoordinatorLimits &limits) {
    if (static_cast<std::size_t>(count) > limits.max_bodies)
        throw ProtocolError(
            pb::Error::CODE_MALFORMED,
            std::string("Hello ") + what + " " + std::to_string(count) +
                " bodies, more than limits.max_bodies = " + std::to_string(limits.max_bodies));
}

/// A routing id (binary) for the log.
std::string hex(const std::string &bytes) {
    std::string text = "0x";
    char digits[3];
    for (const unsigned char c : bytes) {
        std::snprintf(digits, sizeof digits, "%02x", c);
        text += digits;
    }
    return text;
}

} // namespace

Declaration admitHello(const pb::Envelope &e, const ParticipantSpec &spec,
                       const CoordinatorLimits &limits,
                       const std::optional<std::string> &curve_name) {
    const auto &h = e.hello();
    if (h.protocol_major() != kProtocolMajor)
        throw ProtocolError(pb::Error::CODE_VERSION_MISMATCH,
                            "speaks protocol major version " + std::to_string(h.protocol_major()) +
                                ", the coordinator speaks " + std::to_string(kProtocolMajor));
    if (h.participant() != e.sender())
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "says Hello as '" + printable(h.participant()) +
                                "' in an envelope from '" + printable(e.sender()) + "'");
    if (curve_name && *curve_name != spec.name)
        throw ProtocolError(
            pb::Error::CODE_UNKNOWN_PARTICIPANT,
            "says Hello as '" + spec.name + "' with the CURVE key of " +
                (curve_name->empty() ? std::string("no participant") : "'" + *curve_name + "'") +
                " (each participant joins with its own <name>.key)");
    if (e.sequence() != 1)
        throw ProtocolError(pb::Error::CODE_MALFORMED,
                            "Hello must be its first message (sequence " +
                                std::to_string(e.sequence()) + ")");
    checkCount("provides", h.provides_size(), limits);
    checkCount("consumes", h.consumes_size(), limits);
    checkCount("gives initial states of", h.initial_states().states_size(), limits);
    Declaration d;
    d.name = spec.name;
    d.role = codec::fromWire(h.role(), "participant '" + spec.name + "'");
    if (d.role != spec.role)
        throw ProtocolError(pb::Error::CODE_UNKNOWN_PARTICIPANT,
                            std::string("joined as ") + roleName(d.role) +
                                " but the run configures it as " + roleName(spec.role));
    for (const auto &b : h.provides()) {
        checkName(b.name(), limits);
        d.provides.push_back(codec::fromWire(b));
    }
    for (const auto &name : h.consumes())
        checkName(name, limits);
    d.consumes.assign(h.consumes().begin(), h.consumes().end());
    d.initial_states = codec::fromWire(h.initial_states());
    d.capabilities = Capabilities{h.capabilities().rollback(), h.capabilities().checkpoint(),
                                  h.capabilities().triangle_loads()};
    return d;
}

FloodGuard::Verdict FloodGuard::note(const std::string &connection, Clock::time_point now) {
    if (counts_.size() > 4096 && now - last_forget_ > std::chrono::seconds(1))
        forgetQuietOnes(now);
    auto [it, fresh] = counts_.try_emplace(connection, Count{now, 0, false});
    Count &c = it->second;
    if (c.dropped)
        return Verdict::Dropped;
    if (now - c.since >= std::chrono::seconds(1)) {
        c.since = now;
        c.messages = 0;
    }
    if (++c.messages <= max_per_s_)
        return Verdict::Handle;
    c.dropped = true;
    ++dropped_;
    return Verdict::DropNow;
}

/// Keeps the table small when many connections come and go: a connection quiet for 10 s starts
/// afresh if it speaks again (dropped ones stay dropped).
void FloodGuard::forgetQuietOnes(Clock::time_point now) {
    last_forget_ = now;
    for (auto it = counts_.begin(); it != counts_.end();)
        it = !it->second.dropped && now - it->second.since > std::chrono::seconds(10)
                 ? counts_.erase(it)
                 : std::next(it);
}

Lobby::Answer Lobby::receive(const std::string &id, std::string_view bytes, std::size_t frames,
                             const std::optional<std::string> &curve_name, bool open,
                             Clock::time_point now) {
    Answer answer;
    switch (flood_.note(id, now)) {
    case FloodGuard::Verdict::Dropped:
        return answer;
    case FloodGuard::Verdict::DropNow:
        answer.warning = "dropped connection " + hex(id);
        for (const auto &peer : peers_)
            if (peer.heartbeat_id == id)
                answer.warning += " (the heartbeat connection of '" + peer.spec.name + "')";
        answer.warning += ": more than limits.max_stranger_messages_per_s = " +
                          std::to_string(limits_.max_stranger_messages_per_s) +
                          " messages within a second; it is ignored from now on";
        return answer;
    case FloodGuard::Verdict::Handle:
        break;
    }
    if (frames > 1) {
        answer.error = pb::Error::CODE_MALFORMED;
        answer.text = "a message is one frame, not " + std::to_string(frames) + "; ignored";
        answer.warning = "connection " + hex(id) + ": " + answer.text;
        return answer;
    }
    pb::Envelope e;
    try {
        e = codec::decode(bytes.data(), bytes.size(), "a new connection", limits_.maxParts());
    } catch (const ProtocolError &error) {
        if (error.code == pb::Error::CODE_VERSION_MISMATCH)
            return fromVersion(error);
        answer.error = error.code;
        answer.text = error.what();
        answer.warning = "ignored " + std::to_string(bytes.size()) +
                         " bytes from an unknown connection: " + error.what();
        return answer;
    }
    if (e.has_heartbeat()) {
        const auto p = byName(e.sender());
        // With CURVE, only the participant's own key beats for its name.
        if (!p || curve_name.value_or(e.sender()) != e.sender())
            return answer;
        return heartbeat(*p, id, now);
    }
    if (e.has_hello())
        return hello(e, id, curve_name, open, now);
    answer.error = pb::Error::CODE_UNEXPECTED_MESSAGE;
    answer.text = "send Hello first (got " + codec::bodyName(e) + ")";
    answer.warning = codec::bodyName(e) + " from a connection that has not joined; ignored";
    return answer;
}

/// An envelope of another major version: its Hello, if it is one, is refused like any other.
Lobby::Answer Lobby::fromVersion(const ProtocolError &error) {
    return refuse(error.sender, error.code,
                  "speaks protocol major version " + std::to_string(error.version) +
                      ", the coordinator speaks " + std::to_string(kProtocolMajor),
                  "a message from");
}

Lobby::Answer Lobby::heartbeat(std::size_t p, const std::string &id, Clock::time_point now) {
    // The first connection that beats for a name is its heartbeat connection; beats for that
    // name from anywhere else do not keep it alive.
    Peer &peer = peers_[p];
    Answer answer;
    if (peer.heartbeat_id.empty())
        peer.heartbeat_id = id;
    if (peer.heartbeat_id != id) {
        answer.warning =
            "ignored a heartbeat for '" + peer.spec.name + "' from a second connection";
        return answer;
    }
    if (peer.joined)
        peer.last_seen = now;
    answer.heartbeat = true; // answered even before it joined, so it can tell when we are gone
    return answer;
}

Lobby::Answer Lobby::hello(const pb::Envelope &e, const std::string &id,
                           const std::optional<std::string> &curve_name, bool open,
                           Clock::time_point now) {
    Answer answer;
    const auto p = byName(e.sender());
    if (!p) {
        std::string names;
        for (const auto &peer : peers_)
            names += (names.empty() ? "'" : ", '") + peer.spec.name + "'";
        const std::string name = printable(e.hello().participant());
        answer.error = pb::Error::CODE_UNKNOWN_PARTICIPANT;
        answer.text = "this run expects participants " + names + ", not '" + name + "'";
        answer.warning = "refused unknown participant '" + name + "'";
        return answer;
    }
    Peer &peer = peers_[*p];
    if (peer.joined || !open) {
        answer.error = pb::Error::CODE_ALREADY_JOINED;
        answer.text = "participant '" + peer.spec.name +
                      "' already joined this run; a participant cannot rejoin mid-run (resume "
                      "the run from its last checkpoint instead)";
        answer.warning = answer.text;
        return answer;
    }
    try {
        peer.declared = admitHello(e, peer.spec, limits_, curve_name);
    } catch (const ProtocolError &error) {
        return refuse(e.sender(), error.code, error.what(), "a Hello as");
    }
    peer.routing_id = id;
    peer.joined = true;
    peer.received_sequence = 1;
    peer.last_seen = now;
    peer.refusal.clear();
    answer.joined = *p;
    return answer;
}

/// A Hello that joins nobody: the connection is told why, and the reason is kept for the
/// handshake timeout's message when it claimed a name the run expects.
Lobby::Answer Lobby::refuse(const std::string &claimed, pb::Error::Code code,
                            const std::string &why, const char *what) {
    Answer answer;
    answer.error = code;
    answer.text = why;
    answer.warning = std::string("refused ") + what + " '" + printable(claimed) + "': " + why;
    if (const auto p = byName(claimed); p && !peers_[*p].joined)
        peers_[*p].refusal = why;
    return answer;
}

std::optional<std::size_t> Lobby::byName(const std::string &name) const {
    for (std::size_t p = 0; p < peers_.size(); ++p)
        if (peers_[p].spec.name == name)
            return p;
    return std::nullopt;
}

} // namespace grainlink::coupling
