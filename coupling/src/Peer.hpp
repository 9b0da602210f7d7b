#pragma once
// A participant as the coordinator knows it: what the run's file says, what its Hello declared,
// its connections and its message counts. Internal to coupling/.
#include "RunBodies.hpp"
#include "grainlink/coupling/Coordinator.hpp"

#include <chrono>
#include <string>
#include <vector>

namespace grainlink::coupling {

struct Peer {
    ParticipantSpec spec;
    std::string who; ///< "participant '<name>'", for messages
    bool joined = false;
    std::string routing_id;          ///< of its main connection, once joined
    std::string heartbeat_id;        ///< of its heartbeat connection
    Declaration declared;            ///< what its Hello said
    std::vector<std::size_t> inputs; ///< the bodies (indices, body order) whose inputs it gets
    std::uint64_t sent_sequence = 0;
    std::uint64_t received_sequence = 0;
    std::chrono::steady_clock::time_point last_seen;
    std::string refusal; ///< why the last Hello as this participant was refused, until it joins
};

} // namespace grainlink::coupling
