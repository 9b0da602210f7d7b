#pragma once
// The participants' time series: CSV files that a crashed and resumed run continues cleanly.
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace grainlink::apps {

/// Opens a time series CSV. Fresh: the header. Resumed at `restart_s`: the rows up to that
/// time are kept, those after it (computed after the checkpoint, lost with the crash) dropped.
inline std::ofstream openSeries(const std::string &path, const std::string &header,
                                std::optional<double> restart_s) {
    std::vector<std::string> kept;
    if (restart_s) {
        std::ifstream in(path);
        std::string line;
        std::getline(in, line);
        while (std::getline(in, line))
            if (std::stod(line.substr(0, line.find(','))) <= *restart_s + 1e-12)
                kept.push_back(line);
    }
    std::ofstream series(path, std::ios::trunc);
    series << header << '\n';
    for (const auto &line : kept)
        series << line << '\n';
    series.precision(10);
    return series;
}

} // namespace grainlink::apps
