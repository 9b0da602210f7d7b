#include "grainlink/lab/LabPlot.hpp"

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

namespace grainlink::lab {

namespace fs = std::filesystem;

namespace {

/// `text` as one word for /bin/sh.
std::string shellQuoted(const std::string &text) {
    std::string out = "'";
    for (char c : text)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

/// The last non-empty line of `text`.
std::string lastLine(const std::string &text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty())
            last = line;
    return last;
}

} // namespace

std::string labPlotTool() {
    return GRAINLINK_PLOT_LAB_PY; // lab/CMakeLists.txt
}

PlotOutcome plotLabRun(const std::string &directory, const std::string &test,
                       const std::string &python, const std::string &tool) {
    if (!fs::exists(python))
        return {false, "no plot: " + python +
                           " not found (scripts/install-deps installs python3 "
                           "and python3-matplotlib)"};
    if (!fs::exists(tool))
        return {false, "no plot: " + tool + " not found"};
    const fs::path png = fs::path(directory) / (test + ".png");
    std::error_code ignored;
    fs::remove(png, ignored); // an earlier run's plot must not stand for this run
    const std::string command =
        shellQuoted(python) + " " + shellQuoted(tool) + " " + shellQuoted(directory) + " 2>&1";
    std::fflush(stdout); // the child shares the terminal
    FILE *pipe = popen(command.c_str(), "r");
    if (!pipe)
        return {false, "no plot: cannot start " + python};
    std::string output;
    char buffer[512];
    while (std::fgets(buffer, sizeof buffer, pipe))
        output += buffer;
    const int status = pclose(pipe);
    if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::exists(png))
        return {true, "plot: " + png.string()};
    const std::string why = lastLine(output); // the tool's own reason, e.g. matplotlib missing
    return {false, "no plot: " + (why.empty() ? tool + " failed" : why)};
}

} // namespace grainlink::lab
