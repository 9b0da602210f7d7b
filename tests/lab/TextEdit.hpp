#pragma once
// The lab tests' input errors: a valid scenario text with one piece replaced.
#include <catch2/catch.hpp>

#include <string>

/// `text` with its first `from` replaced by `to`; `from` must occur.
inline std::string replacedOnce(std::string text, const std::string &from, const std::string &to) {
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}
