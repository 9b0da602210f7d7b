#pragma once
// ZeroMQ socket set-up shared by the coordinator and the participants. Internal to coupling/.
#include "Codec.hpp"
#include "grainlink/coupling/Security.hpp"

#include <zmq.hpp>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace grainlink::coupling::sockets {

using Clock = std::chrono::steady_clock;

/// One ZeroMQ context per process, shared by the coordinator and every participant in it, so
/// inproc:// endpoints connect them (tests). Never terminated: sockets close themselves.
inline zmq::context_t &processContext() {
    static auto *context = new zmq::context_t(1);
    return *context;
}

/// The ZeroMQ context of one coordinator or participant. inproc:// endpoints connect only within
/// one context, so they share the process-wide one (tests); any other endpoint gets its own, which
/// its destructor terminates: queued messages (a final Shutdown or Error) then leave before the
/// process exits, waiting at most each socket's linger. Declare it before the sockets.
class ContextFor {
public:
    explicit ContextFor(const std::string &endpoint) {
        if (endpoint.rfind("inproc://", 0) != 0)
            own_ = std::make_unique<zmq::context_t>(1);
    }
    zmq::context_t &get() { return own_ ? *own_ : processContext(); }

private:
    std::unique_ptr<zmq::context_t> own_;
};

/// A fresh inproc:// address for a socket monitor. Numbered, never an object's address: a
/// closed socket gives its address back only later, so a reused one could still be taken.
inline std::string monitorAddress(const char *what) {
    static std::atomic<unsigned long> next{0};
    return std::string("inproc://grainlink-") + what + "-" + std::to_string(++next);
}

inline double secondsSince(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

inline void makeCurveClient(zmq::socket_t &socket, const CurveClientKeys &keys) {
    socket.set(zmq::sockopt::curve_serverkey, keys.coordinator_public_key);
    socket.set(zmq::sockopt::curve_publickey, keys.participant.public_key);
    socket.set(zmq::sockopt::curve_secretkey, keys.participant.secret_key);
}

/// A DEALER (participant side), not yet connected; linger bounds how long unsent messages keep
/// a process.
inline zmq::socket_t makeDealer(zmq::context_t &context,
                                const std::optional<CurveClientKeys> &curve, int linger_ms) {
    zmq::socket_t socket(context, zmq::socket_type::dealer);
    socket.set(zmq::sockopt::linger, linger_ms);
    socket.set(zmq::sockopt::rcvtimeo, 50);
    if (curve)
        makeCurveClient(socket, *curve);
    return socket;
}

/// The same, connected.
inline zmq::socket_t connectDealer(zmq::context_t &context, const std::string &endpoint,
                                   const std::optional<CurveClientKeys> &curve, int linger_ms) {
    zmq::socket_t socket = makeDealer(context, curve, linger_ms);
    socket.connect(endpoint);
    return socket;
}

/// Receives one message, waiting at most the socket's receive timeout (`rcvtimeo`, set when the
/// socket is made); false on timeout or when a signal (Ctrl-C) interrupted the wait. One system
/// call where poll-then-receive takes two: this is on every window's path.
inline bool receive(zmq::socket_t &socket, zmq::message_t &message) {
    try {
        return socket.recv(message, zmq::recv_flags::none).has_value();
    } catch (const zmq::error_t &error) {
        if (error.num() == EINTR)
            return false;
        throw;
    }
}

/// The envelope's bytes, serialized straight into a ZeroMQ message (no string, no copy).
inline zmq::message_t encode(const codec::pb::Envelope &envelope) {
    zmq::message_t message(envelope.ByteSizeLong());
    envelope.SerializeWithCachedSizesToArray(static_cast<std::uint8_t *>(message.data()));
    return message;
}

inline void send(zmq::socket_t &socket, const codec::pb::Envelope &envelope) {
    socket.send(encode(envelope), zmq::send_flags::none);
}

/// Waits up to `timeout_ms` for a message; false on timeout or when a signal (Ctrl-C)
/// interrupted the wait, so the caller can look at its stop flag.
inline bool poll(zmq::socket_t &socket, long timeout_ms) {
    zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
    try {
        return zmq::poll(&item, 1, std::chrono::milliseconds(timeout_ms)) > 0;
    } catch (const zmq::error_t &error) {
        if (error.num() == EINTR)
            return false;
        throw;
    }
}

} // namespace grainlink::coupling::sockets
