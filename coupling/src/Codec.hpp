#pragma once
// Conversion between the plain coupling types and the wire messages (grainlink.v1), and the
// envelope checks every received message goes through. Internal to coupling/.
#include "grainlink/coupling/Types.hpp"
#include "grainlink/v1/coupling.pb.h"

#include <google/protobuf/arena.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace grainlink::coupling::codec {

namespace pb = grainlink::v1;

/// A received message that breaks the protocol; `code` says how.
class ProtocolError : public CouplingError {
public:
    ProtocolError(pb::Error::Code code, const std::string &what, std::string sender = {},
                  std::uint32_t version = 0)
        : CouplingError(what), code(code), sender(std::move(sender)), version(version) {}
    pb::Error::Code code;
    std::string sender;        ///< the envelope's sender when the bytes parsed, else empty
    std::uint32_t version = 0; ///< the envelope's version when the bytes parsed
};

void toWire(const Vec3 &v, pb::Vec3 *out);
Vec3 fromWire(const pb::Vec3 &v);

void toWire(const BodyDescription &body, pb::BodyDescription *out);
BodyDescription fromWire(const pb::BodyDescription &body);

void toWire(const BodyState &state, pb::BodyState *out);
BodyState fromWire(const pb::BodyState &state);
void toWire(const std::vector<BodyState> &states, Ticks tick, pb::BodyStates *out);
/// Only the states `which` picks (indices into `states`, in that order).
void toWire(const std::vector<BodyState> &states, const std::vector<std::size_t> &which, Ticks tick,
            pb::BodyStates *out);
std::vector<BodyState> fromWire(const pb::BodyStates &states);
/// The same into `out`, reusing its storage.
void fromWire(const pb::BodyStates &states, std::vector<BodyState> &out);

void toWire(const Wrench &wrench, pb::BodyWrench *out);
Wrench fromWire(const pb::BodyWrench &wrench);
void toWire(const std::vector<Wrench> &wrenches, Ticks start, Ticks end, pb::BodyWrenches *out);
/// Only the wrenches `which` picks (indices into `wrenches`, in that order).
void toWire(const std::vector<Wrench> &wrenches, const std::vector<std::size_t> &which, Ticks start,
            Ticks end, pb::BodyWrenches *out);
std::vector<Wrench> fromWire(const pb::BodyWrenches &wrenches);
/// The same into `out`, reusing its storage.
void fromWire(const pb::BodyWrenches &wrenches, std::vector<Wrench> &out);

pb::Role toWire(Role role);
Role fromWire(pb::Role role, const std::string &who);
pb::Scheme toWire(SchemeKind scheme);
SchemeKind fromWire(pb::Scheme scheme);

std::string encode(const pb::Envelope &envelope);

/// Parses and checks an envelope: well-formed bytes, our major version, a body set.
/// `from` names the peer in error messages. With `max_parts`, bytes that would unpack into more
/// sub-messages and strings than that are refused before any is made: a few bytes each on the
/// wire, ~70 bytes each in memory, so the message size alone does not bound what parsing takes.
pb::Envelope decode(const void *data, std::size_t size, const std::string &from,
                    std::size_t max_parts = SIZE_MAX);

/// The same into `out` (an empty envelope, e.g. ScratchEnvelope::fresh()).
void decode(const void *data, std::size_t size, const std::string &from, pb::Envelope &out,
            std::size_t max_parts = SIZE_MAX);

/// An envelope whose memory is kept from one message to the next: it lives on an arena with a
/// fixed first block that is reset for each message, so building or parsing the messages of a
/// window allocates nothing. One per direction and thread.
class ScratchEnvelope {
public:
    ScratchEnvelope();
    ScratchEnvelope(const ScratchEnvelope &) = delete;
    ScratchEnvelope &operator=(const ScratchEnvelope &) = delete;

    /// A new, empty envelope; the previous one, and all that pointed into it, is gone.
    pb::Envelope &fresh();

private:
    static constexpr std::size_t kBlockBytes = 16 * 1024; ///< holds a window's message (~1 kB)
    std::unique_ptr<char[]> block_;
    google::protobuf::Arena arena_;
};

/// The name of the envelope's body ("hello", "advance_to", ...), for messages.
std::string bodyName(const pb::Envelope &envelope);

/// "window_done for window 5": what a message is, for "sent ... while ... waited for ...".
std::string describe(const pb::Envelope &envelope);

/// Text a peer sent, fit for one log line or error message: bytes outside printable ASCII as
/// `\xNN` (a newline cannot forge a log line), and at most `max_bytes` of it, then how long it was.
std::string printable(std::string_view text, std::size_t max_bytes = 64);

/// Checks the envelope's header against the peer it came from: signed with its `name`, and
/// numbered `last_sequence + 1` (a repeat is a duplicate, a gap out of order).
void checkHeader(const pb::Envelope &envelope, const std::string &name,
                 std::uint64_t last_sequence);

} // namespace grainlink::coupling::codec
