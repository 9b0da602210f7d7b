#pragma once
// Wall-clock time per named phase of the step; printed as a table at the end of a run.
#include <chrono>
#include <string>
#include <vector>

namespace grainlink::dem {

class PhaseTimer {
public:
    /// Index of a phase, created on first use; phases keep their first-use order.
    int phase(const std::string &name);
    void add(int phase, double seconds) { seconds_[phase] += seconds; }
    double total() const;
    std::string table() const;
    void reset();

    /// Adds the lifetime of this object to one phase.
    class Scope {
    public:
        Scope(PhaseTimer &timer, int phase)
            : timer_(timer), phase_(phase), start_(std::chrono::steady_clock::now()) {}
        ~Scope() {
            timer_.add(
                phase_,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
        }
        Scope(const Scope &) = delete;
        Scope &operator=(const Scope &) = delete;

    private:
        PhaseTimer &timer_;
        int phase_;
        std::chrono::steady_clock::time_point start_;
    };

private:
    std::vector<std::string> names_;
    std::vector<double> seconds_;
};

} // namespace grainlink::dem
