#pragma once
// The coordinator's CURVE gatekeeper: a ZAP handler (ZeroMQ's authentication protocol, RFC 27)
// that admits a connection only with one of the participants' public keys and binds it to that
// participant's name, plus a watch on the handshakes that fail before ZAP is asked (a peer
// without CURVE, or with another coordinator key). Internal to coupling/.
#include "grainlink/coupling/Security.hpp"

#include <zmq.hpp>

#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace grainlink::coupling {

/// The answer to one ZAP request. A known key gets "200" and the name of its <name>.pub as
/// `user_id`, which ZeroMQ then attaches to every message of the connection ("User-Id").
struct ZapReply {
    std::string status_code; ///< "200" admitted, "400" refused
    std::string status_text;
    std::string user_id;
};

/// `request` holds the request's frames: version, request id, domain, address, routing id,
/// mechanism, client key (32 bytes). `name_by_key` maps Z85 public keys to participant names.
ZapReply answerZap(const std::vector<std::string> &request,
                   const std::map<std::string, std::string> &name_by_key);

class Authenticator {
public:
    /// Answers ZAP requests of `context` on a thread; watches `router`'s handshakes. Call before
    /// `router` binds, and destroy before closing it.
    Authenticator(zmq::context_t &context, zmq::socket_t &router, const CurveServerKeys &keys);
    ~Authenticator();
    Authenticator(const Authenticator &) = delete;
    Authenticator &operator=(const Authenticator &) = delete;

    /// Empty when no connection was refused; else, for the handshake-timeout message,
    /// "3 connection(s) refused by CURVE authentication: 2 with a public key not among the
    /// participants' (last ...), 1 without CURVE".
    std::string refusals() const;

private:
    void serve(zmq::socket_t handler, zmq::socket_t monitor);
    void countHandshakeFailure(const zmq::message_t &event);

    zmq::socket_t &router_;
    std::map<std::string, std::string> name_by_key_;
    std::thread thread_;
    std::atomic<bool> stop_{false};
    mutable std::mutex mutex_; // guards what follows (the thread writes, refusals() reads)
    unsigned unknown_key_ = 0, no_curve_ = 0, other_coordinator_key_ = 0, broken_off_ = 0,
             other_failure_ = 0;
    std::string last_unknown_key_;
};

} // namespace grainlink::coupling
