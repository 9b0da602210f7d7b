#include "grainlink/dem/PhaseTimer.hpp"

#include <cstdio>
#include <numeric>

namespace grainlink::dem {

int PhaseTimer::phase(const std::string &name) {
    for (std::size_t k = 0; k < names_.size(); ++k)
        if (names_[k] == name)
            return int(k);
    names_.push_back(name);
    seconds_.push_back(0.0);
    return int(names_.size() - 1);
}

double PhaseTimer::total() const {
    return std::accumulate(seconds_.begin(), seconds_.end(), 0.0);
}

std::string PhaseTimer::table() const {
    const double sum = total();
    std::string out = "phase                    time [s]   share\n";
    char line[128];
    for (std::size_t k = 0; k < names_.size(); ++k) {
        std::snprintf(line, sizeof line, "%-22s %10.3f  %5.1f %%\n", names_[k].c_str(), seconds_[k],
                      sum > 0.0 ? 100.0 * seconds_[k] / sum : 0.0);
        out += line;
    }
    std::snprintf(line, sizeof line, "%-22s %10.3f\n", "total", sum);
    return out + line;
}

void PhaseTimer::reset() {
    for (double &s : seconds_)
        s = 0.0;
}

} // namespace grainlink::dem
