#pragma once
// A participant's watch on its connection's ZeroMQ handshakes until the Welcome: CURVE keys the
// coordinator refuses, or CURVE on one side only, then fail at once with the reason instead of
// waiting out the handshake timeout in silence. Internal to coupling/.
#include "grainlink/coupling/Security.hpp"

#include <zmq.hpp>

#include <optional>
#include <string>

namespace grainlink::coupling {

class HandshakeWatch {
public:
    /// Watches `socket` (before it connects, so no attempt is missed). `curve`: its keys, if any.
    HandshakeWatch(zmq::context_t &context, zmq::socket_t &socket,
                   const std::optional<CurveClientKeys> &curve, std::string endpoint);
    ~HandshakeWatch();
    HandshakeWatch(const HandshakeWatch &) = delete;
    HandshakeWatch &operator=(const HandshakeWatch &) = delete;

    /// Why this connection cannot reach the coordinator, once that is clear; nothing meanwhile.
    /// Never waits.
    std::optional<std::string> failure();

private:
    std::optional<std::string> explain(std::uint16_t event, std::uint32_t value);

    zmq::socket_t &socket_;
    zmq::socket_t monitor_;
    bool curve_;
    std::string public_key_; ///< Z85, with CURVE
    std::string endpoint_;
    unsigned unexplained_ = 0; ///< handshakes that failed without a reason
    bool succeeded_ = false;
};

} // namespace grainlink::coupling
