#pragma once
// A hand-driven connection to the coordinator that speaks raw wire messages, so tests can play
// a participant that breaks the protocol on purpose.
#include "grainlink/coupling/Types.hpp"
#include "grainlink/v1/coupling.pb.h"

#include <zmq.hpp>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::testing {

namespace pb = grainlink::v1;

class RawPeer {
public:
    RawPeer(const std::string &endpoint, std::string name)
        : socket_(context_, zmq::socket_type::dealer), name_(std::move(name)) {
        socket_.set(zmq::sockopt::linger, 0);
        socket_.connect(endpoint);
    }

    pb::Envelope envelope(std::uint64_t window = 0) {
        pb::Envelope e;
        e.set_version(coupling::kProtocolMajor);
        e.set_sender(name_);
        e.set_sequence(++sequence_);
        e.set_window(window);
        return e;
    }

    /// Hello as a soil participant consuming `body`.
    void helloAsSoil(const std::string &body = "mass1",
                     std::uint32_t version = coupling::kProtocolMajor) {
        pb::Envelope e = envelope();
        e.set_version(version);
        auto *h = e.mutable_hello();
        h->set_protocol_major(version);
        h->set_participant(name_);
        h->set_role(pb::ROLE_SOIL);
        h->add_consumes(body);
        h->mutable_capabilities()->set_rollback(true);
        send(e);
    }

    void send(const pb::Envelope &e) { sendBytes(e.SerializeAsString()); }
    void sendBytes(const std::string &bytes) {
        socket_.send(zmq::buffer(bytes), zmq::send_flags::none);
    }
    /// One message of several frames (our participants always send one).
    void sendFrames(const std::vector<std::string> &frames) {
        for (std::size_t i = 0; i < frames.size(); ++i)
            socket_.send(zmq::buffer(frames[i]),
                         i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    }

    /// The next message, or nothing within `timeout_ms`.
    std::optional<pb::Envelope> receive(long timeout_ms = 5000) {
        zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
        if (zmq::poll(&item, 1, std::chrono::milliseconds(timeout_ms)) <= 0)
            return std::nullopt;
        zmq::message_t m;
        (void)socket_.recv(m, zmq::recv_flags::none);
        pb::Envelope e;
        e.ParseFromArray(m.data(), static_cast<int>(m.size()));
        return e;
    }

    /// Answers an AdvanceTo for the soil side with a zero wrench on mass1.
    void answerWindow(const pb::Envelope &advance, std::uint64_t sequence_skip = 0,
                      std::uint64_t end_tick_offset = 0) {
        pb::Envelope e = envelope(advance.window());
        e.set_sequence(e.sequence() + sequence_skip);
        auto *done = e.mutable_window_done();
        done->set_end_tick(advance.advance_to().end_tick() + end_tick_offset);
        done->set_iteration(advance.advance_to().iteration());
        auto *w = done->mutable_wrenches()->add_wrenches();
        w->set_body("mass1");
        w->mutable_force_n();
        w->mutable_torque_n_m();
        w->set_frame(pb::FRAME_WORLD);
        send(e);
    }

    /// How many messages arrive until none came for `quiet_ms`.
    int countUntilQuiet(long quiet_ms = 500) {
        int n = 0;
        while (receive(quiet_ms))
            ++n;
        return n;
    }

    /// Drops messages other than `wanted` (for example the heartbeat echoes).
    std::optional<pb::Envelope> receiveUntil(pb::Envelope::BodyCase wanted,
                                             long timeout_ms = 5000) {
        const auto start = std::chrono::steady_clock::now();
        while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(timeout_ms)) {
            auto e = receive(100);
            if (e && e->body_case() == wanted)
                return e;
        }
        return std::nullopt;
    }

private:
    zmq::context_t context_{1};
    zmq::socket_t socket_;
    std::string name_;
    std::uint64_t sequence_ = 0;
};

} // namespace grainlink::testing
