#include "Authenticator.hpp"

#include "Sockets.hpp"

#include <spdlog/spdlog.h>

#include <cstring>

namespace grainlink::coupling {

ZapReply answerZap(const std::vector<std::string> &request,
                   const std::map<std::string, std::string> &name_by_key) {
    if (request.size() != 7 || request[0] != "1.0" || request[5] != "CURVE" ||
        request[6].size() != 32)
        return {"400", "malformed ZAP request", ""};
    char z85[41];
    zmq_z85_encode(z85, reinterpret_cast<const std::uint8_t *>(request[6].data()), 32);
    const auto known = name_by_key.find(z85);
    if (known == name_by_key.end())
        return {"400", std::string("unknown key ") + z85, ""};
    return {"200", "OK", known->second};
}

Authenticator::Authenticator(zmq::context_t &context, zmq::socket_t &router,
                             const CurveServerKeys &keys)
    : router_(router) {
    for (const auto &[name, key] : keys.allowed_participants)
        name_by_key_[key] = name;
    // ZeroMQ asks whatever is bound here whether to admit each CURVE client.
    zmq::socket_t handler(context, zmq::socket_type::rep);
    handler.bind("inproc://zeromq.zap.01");
    const std::string watch = sockets::monitorAddress("handshakes");
    if (zmq_socket_monitor(router.handle(), watch.c_str(),
                           ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                               ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) != 0)
        throw zmq::error_t();
    zmq::socket_t monitor(context, zmq::socket_type::pair);
    monitor.connect(watch);
    thread_ = std::thread(&Authenticator::serve, this, std::move(handler), std::move(monitor));
}

Authenticator::~Authenticator() {
    stop_ = true;
    thread_.join();
    zmq_socket_monitor(router_.handle(), nullptr, 0);
}

void Authenticator::serve(zmq::socket_t handler, zmq::socket_t monitor) {
    zmq::pollitem_t items[] = {{handler.handle(), 0, ZMQ_POLLIN, 0},
                               {monitor.handle(), 0, ZMQ_POLLIN, 0}};
    while (!stop_) {
        try {
            if (zmq::poll(items, 2, std::chrono::milliseconds(100)) <= 0)
                continue;
        } catch (const zmq::error_t &) { // EINTR: a signal; look at the stop flag
            continue;
        }
        if (items[1].revents & ZMQ_POLLIN) {
            zmq::message_t event, endpoint;
            (void)monitor.recv(event, zmq::recv_flags::none);
            (void)monitor.recv(endpoint, zmq::recv_flags::none);
            countHandshakeFailure(event);
        }
        if (!(items[0].revents & ZMQ_POLLIN))
            continue;
        std::vector<std::string> request;
        zmq::message_t frame;
        do {
            (void)handler.recv(frame, zmq::recv_flags::none);
            request.push_back(frame.to_string());
        } while (frame.more());
        const ZapReply reply = answerZap(request, name_by_key_);
        if (reply.status_code != "200") {
            std::lock_guard<std::mutex> lock(mutex_);
            const std::string key = reply.status_text.rfind("unknown key ", 0) == 0
                                        ? reply.status_text.substr(12)
                                        : "?";
            if (unknown_key_++ == 0 || key != last_unknown_key_) // not once per reconnect
                spdlog::warn("coordinator: refused a CURVE connection from {} with public key {} "
                             "(not among the participants' keys)",
                             request.size() > 3 ? request[3] : "?", key);
            last_unknown_key_ = key;
        }
        handler.send(zmq::str_buffer("1.0"), zmq::send_flags::sndmore);
        handler.send(zmq::buffer(request.size() > 1 ? request[1] : std::string()),
                     zmq::send_flags::sndmore);
        handler.send(zmq::buffer(reply.status_code), zmq::send_flags::sndmore);
        handler.send(zmq::buffer(reply.status_text), zmq::send_flags::sndmore);
        handler.send(zmq::buffer(reply.user_id), zmq::send_flags::sndmore);
        handler.send(zmq::str_buffer(""), zmq::send_flags::none);
    }
}

void Authenticator::countHandshakeFailure(const zmq::message_t &event) {
    if (event.size() < 6)
        return;
    std::uint16_t id = 0;
    std::uint32_t error = 0;
    std::memcpy(&id, event.data(), sizeof id);
    std::memcpy(&error, static_cast<const char *>(event.data()) + 2, sizeof error);
    // Whichever side notices a mechanism mismatch first names it; the other sees the connection
    // break off (no detail).
    const bool no_detail = id == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL;
    std::lock_guard<std::mutex> lock(mutex_);
    unsigned &count = no_detail                                             ? broken_off_
                      : error == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH ? no_curve_
                      : error == ZMQ_PROTOCOL_ERROR_ZMTP_CRYPTOGRAPHIC      ? other_coordinator_key_
                                                                            : other_failure_;
    if (count++ == 0) // a client retries every 0.1 s: the first of each kind is logged
        spdlog::warn("coordinator: refused a connection that {}",
                     &count == &no_curve_ ? "speaks without CURVE"
                     : &count == &other_coordinator_key_
                         ? "encrypts for another coordinator key (its coordinator.pub is not ours)"
                     : &count == &broken_off_ ? "broke off the CURVE handshake (no CURVE keys?)"
                                              : "failed the CURVE handshake");
}

std::string Authenticator::refusals() const {
    std::lock_guard<std::mutex> lock(mutex_);
    const unsigned total =
        unknown_key_ + no_curve_ + other_coordinator_key_ + broken_off_ + other_failure_;
    if (total == 0)
        return "";
    std::string text = std::to_string(total) + " connection(s) refused by CURVE authentication:";
    auto part = [&text, first = true](unsigned n, const std::string &what) mutable {
        if (n == 0)
            return;
        text += (first ? " " : ", ") + std::to_string(n) + " " + what;
        first = false;
    };
    part(unknown_key_,
         "with a public key not among the participants' (last " + last_unknown_key_ + ")");
    part(no_curve_, "without CURVE");
    part(other_coordinator_key_, "encrypting for another coordinator key");
    part(broken_off_, "breaking off the handshake");
    part(other_failure_, "failing the handshake otherwise");
    return text;
}

} // namespace grainlink::coupling
