#include "OutputCheck.hpp"

#include "Codec.hpp"

#include <algorithm>

namespace grainlink::coupling {

namespace {

bool finite(const BodyState &s) {
    return s.position_m.allFinite() && s.orientation.coeffs().allFinite() &&
           s.linear_velocity_m_s.allFinite() && s.angular_velocity_rad_s.allFinite();
}

bool finite(const Wrench &w) {
    return w.force_N.allFinite() && w.torque_N_m.allFinite();
}

std::string nonFinite(const BodyState &s) {
    return "non-finite state of body '" + codec::printable(s.body) + "'";
}

std::string nonFinite(const Wrench &w) {
    return "non-finite wrench on body '" + codec::printable(w.body) + "'";
}

std::string list(const std::vector<std::string> &names) {
    std::string text = "{";
    for (const auto &n : names)
        text += " " + codec::printable(n);
    return text + " }";
}

template <typename T>
std::optional<OutputProblem> check(const char *what, const std::vector<T> &outputs,
                                   const std::vector<std::string> &expected) {
    bool in_order = outputs.size() == expected.size();
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        if (!finite(outputs[i]))
            return OutputProblem{OutputProblem::Kind::NonFinite, nonFinite(outputs[i])};
        in_order = in_order && outputs[i].body == expected[i];
    }
    if (in_order)
        return std::nullopt;
    std::vector<std::string> names, sorted_expected = expected;
    for (const auto &x : outputs)
        names.push_back(x.body);
    std::sort(names.begin(), names.end());
    std::sort(sorted_expected.begin(), sorted_expected.end());
    if (names == sorted_expected)
        return std::nullopt;
    return OutputProblem{OutputProblem::Kind::WrongBodies,
                         std::string(what) + " for " + list(names) +
                             " but must give exactly one for each of " + list(sorted_expected)};
}

} // namespace

std::optional<OutputProblem> checkOutputs(const std::vector<BodyState> &outputs,
                                          const std::vector<std::string> &expected) {
    return check("states", outputs, expected);
}

std::optional<OutputProblem> checkOutputs(const std::vector<Wrench> &outputs,
                                          const std::vector<std::string> &expected) {
    return check("wrenches", outputs, expected);
}

} // namespace grainlink::coupling
