// The packing cache under concurrent runs: real `grainlink dem` processes needing the same
// packing at once settle it once; the others wait for it, read it whole and run on it to the
// same result.
#include "StudyFixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::study::test;

TEST_CASE("processes needing one packing at once settle it once and get identical results",
          "[study][cache]") {
    TempFolder folder("cache");
    // The test scenario with a longer settling (~0.5 s wall), so the others surely start
    // while the first is settling.
    std::string scenario = readFile(kData + "/plate.yaml");
    const std::string settle = "max_settle_time_s: 0.2";
    scenario.replace(scenario.find(settle), settle.size(), "max_settle_time_s: 0.8");
    writeFile(folder / "plate.yaml", scenario);
    const std::string cache = folder / "packings";
    auto dem = [&](const std::string &name) {
        return std::vector<std::string>{kGrainlink, "dem", folder / "plate.yaml", "--out",
                                        folder / name};
    };
    Process first(dem("first"), folder.path, folder / "first.log");
    // Its lock file appears as it starts settling (it holds the lock from then on).
    REQUIRE(waitUntil(
        [&] {
            if (!fs::exists(cache))
                return false;
            for (const auto &e : fs::directory_iterator(cache))
                if (e.path().extension() == ".lock")
                    return true;
            return false;
        },
        20.0));
    Process second(dem("second"), folder.path, folder / "second.log");
    Process third(dem("third"), folder.path, folder / "third.log");
    CHECK(first.wait() == 0);
    CHECK(second.wait() == 0);
    CHECK(third.wait() == 0);

    const std::string settled_log = readFile(folder / "first.log");
    CHECK(count(settled_log, "particles, settled") == 1);
    CHECK(count(settled_log, "reusing cached packing") == 0);
    for (const char *reader : {"second", "third"}) {
        INFO(reader);
        const std::string log = readFile(folder / (std::string(reader) + ".log"));
        CHECK(count(log, "another process is settling this packing: waiting for it") == 1);
        CHECK(count(log, "reusing cached packing") == 1);
        CHECK(count(log, "particles, settled") == 0);
        CHECK(readFile(folder / (std::string(reader) + "/series.csv")) ==
              readFile(folder / "first/series.csv"));
        CHECK(withoutWallTime(nlohmann::json::parse(
                  readFile(folder / (std::string(reader) + "/summary.json")))) ==
              withoutWallTime(nlohmann::json::parse(readFile(folder / "first/summary.json"))));
    }
    // One packing file, no temporary left behind.
    int files = 0;
    for (const auto &e : fs::directory_iterator(cache))
        files += e.path().extension() == ".bin";
    CHECK(files == 1);
}
