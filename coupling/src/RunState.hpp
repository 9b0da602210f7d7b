#pragma once
// Where the coordinator's run is: its lifecycle state, window and time, and the one line that
// names who failed there and why. No sockets: tests drive it directly. Internal to coupling/.
#include "grainlink/coupling/Coordinator.hpp"

#include <atomic>
#include <string>

namespace grainlink::coupling {

/// Something that stops the run, and who is to blame: a participant ("participant 'soil'"), the
/// coupling, the checkpoint. The coordinator turns it into RunState::failure().
class PeerError : public CouplingError {
public:
    PeerError(std::string who, std::string why)
        : CouplingError(who + ": " + why), who(std::move(who)), why(std::move(why)) {}
    std::string who;
    std::string why;
};

class RunState {
public:
    using State = Coordinator::State;

    explicit RunState(double tick_s) : tick_s_(tick_s) {}

    State state() const { return state_; }
    /// Moves on in the lifecycle Bound → Handshake → Running → Finished, or to Failed from any
    /// state; anything else throws LifecycleError saying what to do.
    void enter(State next);
    /// What to do with a coordinator in this state (for a call that came out of turn).
    const char *whatToDo() const;

    /// "during the handshake", or "in window 7 (t = 0.07 s)".
    std::string where() const;
    /// The run's one-line failure: "<who> failed <where>: <why>".
    std::string failure(const std::string &who, const std::string &why) const;

    std::uint64_t window = 0; ///< the window running now, or next
    Ticks tick = 0;           ///< its start

private:
    double tick_s_;                          ///< [s]
    std::atomic<State> state_{State::Bound}; ///< read by Coordinator::state() from any thread
};

} // namespace grainlink::coupling
