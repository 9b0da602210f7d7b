#include "HandshakeWatch.hpp"

#include "Sockets.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>

namespace grainlink::coupling {

HandshakeWatch::HandshakeWatch(zmq::context_t &context, zmq::socket_t &socket,
                               const std::optional<CurveClientKeys> &curve, std::string endpoint)
    : socket_(socket), monitor_(context, zmq::socket_type::pair), curve_(curve.has_value()),
      public_key_(curve ? curve->participant.public_key : ""), endpoint_(std::move(endpoint)) {
    const std::string address = sockets::monitorAddress("handshake");
    if (zmq_socket_monitor(socket.handle(), address.c_str(),
                           ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL |
                               ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                               ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) != 0)
        throw zmq::error_t();
    monitor_.connect(address);
}

HandshakeWatch::~HandshakeWatch() {
    if (socket_) // still open: stop its events before their reader goes
        zmq_socket_monitor(socket_.handle(), nullptr, 0);
}

std::optional<std::string> HandshakeWatch::failure() {
    zmq::message_t event, address;
    while (!succeeded_ && monitor_.recv(event, zmq::recv_flags::dontwait)) {
        (void)monitor_.recv(address, zmq::recv_flags::none);
        std::uint16_t id = 0;
        std::uint32_t value = 0;
        std::memcpy(&id, event.data(), sizeof id);
        std::memcpy(&value, static_cast<const char *>(event.data()) + 2, sizeof value);
        if (auto why = explain(id, value))
            return why;
    }
    return std::nullopt;
}

std::optional<std::string> HandshakeWatch::explain(std::uint16_t event, std::uint32_t value) {
    const std::string coordinator = "the coordinator at " + endpoint_;
    switch (event) {
    case ZMQ_EVENT_HANDSHAKE_SUCCEEDED:
        succeeded_ = true;
        return std::nullopt;
    case ZMQ_EVENT_HANDSHAKE_FAILED_AUTH:
        return coordinator + " refused this participant's CURVE key (public key " + public_key_ +
               ", status " + std::to_string(value) +
               "): no <name>.pub in its keys directory holds it";
    case ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL:
        if (value == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH)
            return curve_ ? "this participant has CURVE keys but " + coordinator +
                                " runs without CURVE"
                          : coordinator + " requires CURVE and this participant has no keys "
                                          "(give it its <name>.key and coordinator.pub)";
        {
            char code[16];
            std::snprintf(code, sizeof code, "0x%08x", value);
            return "the handshake with " + coordinator + " failed (ZeroMQ protocol error " + code +
                   ")";
        }
    case ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL:
        // What the other side noticed first (a mechanism mismatch, a key it cannot decrypt
        // with) it names on its side; this side sees the connection break off. Three in a row:
        // say what can cause it.
        if (++unexplained_ < 3)
            return std::nullopt;
        return "the handshake with " + coordinator + " failed " + std::to_string(unexplained_) +
               " times without a reason: " +
               (curve_ ? "the coordinator runs without CURVE, or coordinator.pub is not its "
                         "public key"
                       : "the coordinator requires CURVE (give this participant its <name>.key "
                         "and coordinator.pub), or no grainlink coordinator listens there");
    }
    return std::nullopt;
}

} // namespace grainlink::coupling
