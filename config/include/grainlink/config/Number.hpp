#pragma once
// A number as a message or a report prints it: `digits` significant digits, as "%g" does
// (2.1, 0.047, 3.9e+04), the one way every part of grainlink words a figure.
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

namespace grainlink::config {

inline std::string significant(double v, int digits) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

/// A length in metres as millimetres, to four significant digits: "12.35 mm".
inline std::string millimetres(double metres) {
    return significant(metres * 1e3, 4) + " mm";
}

/// The number a whole text reads as ("2.5", "-1e-3"); none where any of it is not the number
/// ("40mm", "", "abc"): the one test of "is this cell or option a number".
inline std::optional<double> wholeNumber(const std::string &text) {
    char *end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size())
        return std::nullopt;
    return v;
}

} // namespace grainlink::config
