#include "WindowReplies.hpp"

#include "OutputCheck.hpp"
#include "RunState.hpp"

#include <cmath>

namespace grainlink::coupling {

WindowReplies::WindowReplies(std::vector<From> participants) : from_(std::move(participants)) {}

void WindowReplies::begin(std::uint64_t window, Ticks end_tick, unsigned iteration) {
    window_ = window;
    end_tick_ = end_tick;
    iteration_ = iteration;
    states_.clear();
    wrenches_.clear();
}

namespace {

/// Appends `got` to `all` once the shared output check passed.
template <typename T>
void keep(const WindowReplies::From &from, std::vector<T> &got, std::vector<T> &all) {
    if (const auto problem = checkOutputs(got, from.outputs))
        throw PeerError(from.who,
                        std::string("sent ") +
                            (problem->kind == OutputProblem::Kind::NonFinite ? "a " : "") +
                            problem->text);
    all.insert(all.end(), got.begin(), got.end());
}

} // namespace

WindowReplies::Reply WindowReplies::read(std::size_t p, const codec::pb::Envelope &e) {
    const From &from = from_[p];
    if (!e.has_window_done() || e.window() != window_)
        throw PeerError(from.who, "sent " + codec::describe(e) +
                                      " while the coordinator waited for WindowDone");
    const auto &done = e.window_done();
    if (done.end_tick() != end_tick_)
        throw PeerError(from.who, "reports end tick " + std::to_string(done.end_tick()) +
                                      " for a window that ends at tick " +
                                      std::to_string(end_tick_));
    if (done.iteration() != iteration_)
        throw PeerError(from.who, "reports iteration " + std::to_string(done.iteration()) +
                                      ", expected " + std::to_string(iteration_));
    try {
        if (from.role == Role::Multibody) {
            codec::fromWire(done.states(), got_states_);
            keep(from, got_states_, states_);
        } else {
            codec::fromWire(done.wrenches(), got_wrenches_);
            keep(from, got_wrenches_, wrenches_);
        }
    } catch (const codec::ProtocolError &error) {
        throw PeerError(from.who, error.what());
    }
    Reply reply;
    for (const auto &w : done.work()) {
        // The coupling's energy balance sums it: one NaN would blind the mismatch guard.
        if (!std::isfinite(w.work_j()))
            throw PeerError(from.who, "sent a non-finite work for body '" +
                                          codec::printable(w.body()) + "'");
        reply.work_J += w.work_j();
    }
    reply.suggested_step_ticks = done.suggested_macro_step_ticks();
    reply.run_complete = done.run_complete();
    return reply;
}

} // namespace grainlink::coupling
