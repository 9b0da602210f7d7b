#pragma once
// Who may join, and what the coordinator answers everyone else: a Hello checked against the
// participant the run expects under its name, a guard that drops connections which flood, and the
// lobby that decides about every message that is not from a joined participant's main connection.
// No sockets: tests call them directly. Internal to coupling/.
#include "Codec.hpp"
#include "Peer.hpp"
#include "RunBodies.hpp"
#include "grainlink/coupling/Coordinator.hpp"

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace grainlink::coupling {

/// The participant a Hello declares, if it is a valid Hello from the participant `spec` describes
/// (Hello.participant = spec.name, already matched by the caller). `curve_name` is the name the
/// connection's CURVE key is bound to (ZeroMQ's User-Id), or nothing without CURVE. Throws
/// codec::ProtocolError with the code and the reason to send back; such a Hello joins nobody.
Declaration admitHello(const codec::pb::Envelope &hello, const ParticipantSpec &spec,
                       const CoordinatorLimits &limits,
                       const std::optional<std::string> &curve_name);

/// Counts the messages of each connection that is not a joined participant's main one (heartbeat
/// connections and strangers), and drops one that sends more than the limit within a second.
class FloodGuard {
public:
    using Clock = std::chrono::steady_clock;
    enum class Verdict {
        Handle,  ///< answer it as usual
        DropNow, ///< over the limit just now: log why, then ignore
        Dropped, ///< dropped earlier: ignore silently
    };

    explicit FloodGuard(unsigned max_messages_per_s) : max_per_s_(max_messages_per_s) {}
    Verdict note(const std::string &connection, Clock::time_point now);
    std::size_t dropped() const { return dropped_; }

private:
    struct Count {
        Clock::time_point since; ///< start of the current one-second interval
        unsigned messages = 0;
        bool dropped = false;
    };
    void forgetQuietOnes(Clock::time_point now);

    unsigned max_per_s_;
    std::map<std::string, Count> counts_; ///< by routing id
    Clock::time_point last_forget_{};
    std::size_t dropped_ = 0;
};

/// Decides about each message from a connection that is not a joined participant's main one: a
/// heartbeat connection, a participant saying Hello, or a stranger. Nothing such a connection
/// sends stops the run or makes it a participant, short of a valid Hello for a name the run
/// expects and nobody has taken; the coordinator sends what the answer says.
class Lobby {
public:
    using Clock = FloodGuard::Clock;
    struct Answer {
        std::optional<codec::pb::Error::Code> error; ///< reply an Error with this code and `text`
        std::string text;
        bool heartbeat = false;            ///< reply the coordinator's Heartbeat
        std::optional<std::size_t> joined; ///< this participant joined with this message
        std::string warning;               ///< a line for the log, printable
    };

    /// `peers`: the run's participants, whose admission state the lobby keeps.
    Lobby(std::vector<Peer> &peers, const CoordinatorLimits &limits)
        : peers_(peers), limits_(limits), flood_(limits.max_stranger_messages_per_s) {}

    /// One message (`frames` frames, the first of them `bytes`) from connection `id`, whose
    /// CURVE key is bound to `curve_name` (nothing without CURVE). `open`: the handshake is on.
    Answer receive(const std::string &id, std::string_view bytes, std::size_t frames,
                   const std::optional<std::string> &curve_name, bool open, Clock::time_point now);

private:
    Answer fromVersion(const codec::ProtocolError &error);
    Answer heartbeat(std::size_t p, const std::string &id, Clock::time_point now);
    Answer hello(const codec::pb::Envelope &e, const std::string &id,
                 const std::optional<std::string> &curve_name, bool open, Clock::time_point now);
    /// `what`: "a Hello as", "a message from" (for the log).
    Answer refuse(const std::string &claimed, codec::pb::Error::Code code, const std::string &why,
                  const char *what);
    std::optional<std::size_t> byName(const std::string &name) const;

    std::vector<Peer> &peers_;
    CoordinatorLimits limits_;
    FloodGuard flood_;
};

} // namespace grainlink::coupling
