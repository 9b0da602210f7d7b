#pragma once
// The plot of a lab run (docs/lab.md): tools/plot_lab.py, run with Debian's /usr/bin/python3,
// reads the run's summary.json and writes <directory>/<test>.png. Without python3 or matplotlib
// there is no plot and a one-line reason; the run's results stay as they are.
#include <string>

namespace grainlink::lab {

/// The project's tools/plot_lab.py (its path in the source tree this library was built from).
std::string labPlotTool();

struct PlotOutcome {
    bool written = false; ///< <directory>/<test>.png exists
    std::string message;  ///< one line: "plot: DIR/TEST.png" or "no plot: why"
};

/// Runs `python tool directory` and reports what came of it; never throws for a missing
/// interpreter, tool or matplotlib (the message says which).
PlotOutcome plotLabRun(const std::string &directory, const std::string &test,
                       const std::string &python = "/usr/bin/python3",
                       const std::string &tool = labPlotTool());

} // namespace grainlink::lab
