#pragma once
// The participants' WindowDone replies of one pass over a window, checked and gathered: the right
// window, end tick and iteration, finite outputs for exactly the bodies each one answers for.
// No sockets: tests feed it envelopes. Internal to coupling/.
#include "Codec.hpp"

#include <string>
#include <vector>

namespace grainlink::coupling {

class WindowReplies {
public:
    /// A participant as the replies see it.
    struct From {
        std::string who; ///< "participant 'soil'"
        Role role = Role::Multibody;
        std::vector<std::string> outputs; ///< the bodies it answers for, in its order
    };
    /// What a WindowDone brought besides the states or wrenches.
    struct Reply {
        double work_J = 0.0;            ///< [J] summed over its bodies
        Ticks suggested_step_ticks = 0; ///< 0: no hint
        bool run_complete = false;
    };

    explicit WindowReplies(std::vector<From> participants);

    /// A new pass: `window` ending at `end_tick`, pass `iteration`; forgets the last pass's.
    void begin(std::uint64_t window, Ticks end_tick, unsigned iteration);
    /// Checks participant `p`'s message; keeps its states (multibody) or wrenches (soil), in
    /// arrival order. Throws PeerError unless it is a valid WindowDone of this pass.
    Reply read(std::size_t p, const codec::pb::Envelope &envelope);

    const std::vector<BodyState> &states() const { return states_; }
    const std::vector<Wrench> &wrenches() const { return wrenches_; }

private:
    std::vector<From> from_;
    std::uint64_t window_ = 0;
    Ticks end_tick_ = 0;
    unsigned iteration_ = 0;
    // Reused every pass (no allocation once warm):
    std::vector<BodyState> states_, got_states_;
    std::vector<Wrench> wrenches_, got_wrenches_;
};

} // namespace grainlink::coupling
