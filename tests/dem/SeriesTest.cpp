// A run's time series (grainlink/dem/Series.hpp) survive crashes: each window's rows are on
// disk when the window ends, a resume keeps only whole rows up to its checkpoint, and those kept
// rows are on disk before the resumed run computes anything (the fault soak lost 61 rows of
// soil.csv to a crash right after a resume, and kept a cut row `0.3` as a row).
#include "grainlink/dem/Series.hpp"

#include "Fixtures.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

using grainlink::dem::Series;
using grainlink::dem::SeriesRestart;
using grainlink::dem::testing::Scratch;
namespace fs = std::filesystem;

namespace {

const std::string kHeader = "time_s,body,Fz_N";

/// What is on disk now (what a crash at this moment would leave).
std::string onDisk(const fs::path &path) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void put(const fs::path &path, const std::string &text) {
    std::ofstream(path) << text;
}

} // namespace

TEST_CASE("Series: each window's rows are on disk when it ends", "[dem][series]") {
    Scratch scratch("series-rows");
    const fs::path path = scratch.dir / "soil.csv";
    Series series(path.string(), kHeader, std::nullopt);
    CHECK(onDisk(path) == kHeader + "\n");
    series.rows() << 0.001 << ",wheel," << 1.5 << '\n' << 0.001 << ",rim," << 2.5 << '\n';
    CHECK(onDisk(path) == kHeader + "\n"); // a window's rows reach the file together ...
    series.write();                        // ... when it ends
    CHECK(onDisk(path) == kHeader + "\n0.001,wheel,1.5\n0.001,rim,2.5\n");
    series.rows() << 0.002 << ",wheel," << 1.0 / 3.0 << '\n';
    series.write();
    CHECK(onDisk(path) == kHeader + "\n0.001,wheel,1.5\n0.001,rim,2.5\n0.002,wheel,0.3333333333\n");
}

TEST_CASE("Series: a resume may count its rows by another column (grainlink dem's step)",
          "[dem][series]") {
    Scratch scratch("series-step");
    const fs::path path = scratch.dir / "series.csv";
    const std::string header = "t_s,run_time_s,step,KE_J";
    // Times print rounded; the step is exact. A crash cut the last row inside its step count:
    // "12" of 1200 is a whole number, but not a whole row.
    const std::string kept = header + "\n0.0003000000001,0,300,1\n0.0006,0.0003,600,2\n";
    put(path, kept + "0.0009,0.0006,900,3\n0.0012,0.0009,12");
    Series series(path.string(), header, SeriesRestart{600.0, 2});
    CHECK(onDisk(path) == kept);
    CHECK_THROWS_AS(Series(path.string(), header, SeriesRestart{600.0, 4}), std::logic_error);
}

TEST_CASE("Series: a resume keeps whole rows up to its checkpoint", "[dem][series]") {
    Scratch scratch("series-resume");
    const fs::path path = scratch.dir / "rig.csv";
    // What a crash can leave: rows computed after the checkpoint at 0.3 s and a last line cut
    // mid-row (no line end), here one whose first cell still reads as a time before it.
    const std::string kept = kHeader + "\n0.1,wheel,1\n0.2,wheel,2\n0.3,wheel,3\n";
    SECTION("rows after the checkpoint and a cut last row are dropped") {
        put(path, kept + "0.4,wheel,4\n0.3");
        Series series(path.string(), kHeader, SeriesRestart{0.3});
        // On disk at once: a crash before the next checkpoint loses nothing kept.
        CHECK(onDisk(path) == kept);
        series.rows() << 0.4 << ",wheel," << 40 << '\n';
        series.write();
        CHECK(onDisk(path) == kept + "0.4,wheel,40\n");
    }
    SECTION("a cut row of all its cells but its line end is dropped") {
        put(path, kept + "0.3,wheel,3.25");
        Series series(path.string(), kHeader, SeriesRestart{0.3});
        CHECK(onDisk(path) == kept);
    }
    SECTION("lines that are not rows are dropped") {
        put(path, kHeader + "\n0.1,wheel,1\n0.15,wh\n0.2,wheel,2\nx,wheel,9\n0.3,wheel,3\n"
                            "0.25,wheel,1,extra\n\n");
        Series series(path.string(), kHeader, SeriesRestart{0.3});
        CHECK(onDisk(path) == kept);
    }
    SECTION("an empty or missing series restarts from the header") {
        put(path, "");
        { Series series(path.string(), kHeader, SeriesRestart{0.3}); }
        CHECK(onDisk(path) == kHeader + "\n");
        fs::remove(path);
        { Series series(path.string(), kHeader, SeriesRestart{0.3}); }
        CHECK(onDisk(path) == kHeader + "\n");
    }
    SECTION("another run's columns are an error") {
        put(path, "time_s,slip\n0.1,0.2\n");
        try {
            Series series(path.string(), kHeader, SeriesRestart{0.3});
            FAIL("no error");
        } catch (const std::runtime_error &e) {
            CHECK(std::string(e.what()) ==
                  path.string() + ": its columns differ from this run's (time_s,slip...): "
                                  "cannot resume");
        }
        CHECK(onDisk(path) == "time_s,slip\n0.1,0.2\n"); // left as it was
    }
    CHECK_FALSE(fs::exists(path.string() + ".partial"));
}
