// The progress line of long runs (dem/Progress): what it says, and when it says nothing.
#include "grainlink/dem/Progress.hpp"

#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

using grainlink::dem::Progress;

namespace {

/// Everything `report` writes through a Progress into a temporary stream.
template <class Report> std::string written(double interval_s, Report report) {
    std::FILE *stream = std::tmpfile();
    REQUIRE(stream != nullptr);
    {
        Progress progress("node", interval_s, stream);
        report(progress);
    }
    std::rewind(stream);
    std::string text;
    for (int c; (c = std::fgetc(stream)) != EOF;)
        text += char(c);
    std::fclose(stream);
    return text;
}

} // namespace

TEST_CASE("a progress line names the simulated time, its share, the wall time and the ETA") {
    const std::string line =
        written(1e-9, [](Progress &p) { p.update(0.25, 0.5, 2'000'000, "phase drive"); });
    CHECK(line.rfind("[node] t = 0.2500 s ( 50.0 %)  wall ", 0) == 0);
    CHECK(line.find("ETA ") != std::string::npos);
    CHECK(line.find("M particle-steps/s  phase drive\n") != std::string::npos);
}

TEST_CASE("a process without grains gets no rate and an interval of 0 no line at all") {
    const std::string multibody =
        written(1e-9, [](Progress &p) { p.update(0.1, 0.2, 0, "slip 0.3"); });
    CHECK(multibody.find("particle-steps") == std::string::npos);
    CHECK(multibody.find("  slip 0.3\n") != std::string::npos);
    CHECK(written(0.0, [](Progress &p) {
              for (int k = 0; k < 100; ++k)
                  p.update(0.01 * k, 0.01 * k, 1000);
          }).empty());
    // Lines come at most once per interval: an hour's interval prints none in a test's time.
    CHECK(written(3600.0, [](Progress &p) { p.update(0.1, 0.5, 1000); }).empty());
}
