// Studies through the local pool, end to end with real `grainlink dem` runs: results do not
// depend on the pool size or the order, runs with one soil setup share one packing, a failed
// point is reported and not retried unless asked, and a killed study resumes where it was.
#include "StudyFixtures.hpp"

#include "grainlink/study/Design.hpp"
#include "grainlink/study/ResultTable.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <map>

using namespace grainlink::study;
using namespace grainlink::study::test;
using nlohmann::json;

namespace {

ExecutorOptions localPool(int jobs, const TempFolder &folder) {
    ExecutorOptions options;
    options.grainlink = kGrainlink;
    options.jobs = jobs;
    options.working_directory = folder.path.string(); // its packings/ cache starts empty
    options.progress_interval_s = 0.5;
    return options;
}

std::map<std::string, PointResult> byId(const std::vector<PointResult> &results) {
    std::map<std::string, PointResult> out;
    for (const PointResult &r : results)
        out[r.point.id] = r;
    return out;
}

} // namespace

TEST_CASE("a point's result depends on neither the pool size nor the order, and one packing per "
          "soil setup",
          "[study][local]") {
    TempFolder one("pool1"), two("pool2");
    const Study serial = loadStudy(kData + "/sweep.yaml", one / "study");
    Study parallel = loadStudy(kData + "/sweep.yaml", two / "study");
    std::reverse(parallel.points.begin(), parallel.points.end());
    std::vector<StudyProgress> progress;
    ExecutorOptions two_jobs = localPool(2, two);
    two_jobs.progress = [&](const StudyProgress &p) { progress.push_back(p); };
    const auto a = byId(run(serial, localPool(1, one)));
    const auto b = byId(run(parallel, two_jobs));
    REQUIRE(a.size() == 4);
    REQUIRE(b.size() == 4);
    for (const auto &[id, r] : a) {
        INFO(r.point.label);
        REQUIRE(r.status == PointStatus::Done);
        REQUIRE(b.at(id).status == PointStatus::Done);
        CHECK(r.ran_now);
        CHECK(readFile(r.folder + "/series.csv") == readFile(b.at(id).folder + "/series.csv"));
        CHECK(withoutWallTime(r.summary) == withoutWallTime(b.at(id).summary));
        CHECK(r.summary.at("steps") == 1200);
    }
    REQUIRE_FALSE(progress.empty());
    CHECK(progress.back().done == 4);
    CHECK(progress.back().running == 0);

    // Two seeds, two plate speeds: each packing settled once, the other run of it reads it.
    for (const auto *results : {&a, &b}) {
        int settled = 0, reused = 0;
        for (const auto &[id, r] : *results) {
            const std::string log = readFile(r.log);
            settled += count(log, "particles, settled");
            reused += count(log, "reusing cached packing");
        }
        CHECK(settled == 2);
        CHECK(reused == 2);
    }

    // The table's means are the replicates' means of the points' own summaries.
    const TableFiles files = writeTables(serial, run(serial, localPool(1, one)));
    CHECK(files.warnings.empty());
    std::map<std::string, std::vector<double>> forces;
    for (const auto &[id, r] : a)
        forces[r.point.settings[0].second].push_back(
            r.summary["bodies"]["plate"]["force_N"][2].get<double>());
    const std::string table = readFile(files.table_csv);
    for (const auto &[speed, values] : forces) {
        char mean[40];
        std::snprintf(mean, sizeof mean, "%.10g", (values[0] + values[1]) / 2.0);
        INFO(table);
        CHECK_THAT(table, Catch::Contains("\"" + speed + "\",2,2," + mean + ","));
    }

    // The plot script reads the same table: one panel per observable and varied key.
    std::string plotted;
    REQUIRE(runToEnd({"/usr/bin/python3", kSource + "/tools/plot_study.py", one / "study"},
                     one.path.string(), plotted) == 0);
    CHECK_THAT(plotted, Catch::Contains("2 observables x 1 varied key, 2 design points"));
    CHECK(fs::exists(one / "study/study.png"));
}

TEST_CASE("a failed point is reported with its error and log while the others go on, and it is "
          "rerun only when asked",
          "[study][local]") {
    TempFolder folder("failed");
    // An overlap limit no settling bed keeps: a valid scenario whose run stops.
    writeFile(folder / "failing.yaml",
              "name: failing\nbase: {kind: dem, scenario: " + kData +
                  "/plate.yaml}\n"
                  "design:\n  vary:\n"
                  "    - {key: simulation.max_overlap_ratio, values: [0.4, 1.0e-6]}\n"
                  "observables: [final_time_s]\n");
    const Study s = loadStudy(folder / "failing.yaml", folder / "study");
    const std::vector<PointResult> first = run(s, localPool(1, folder));
    REQUIRE(first.size() == 2);
    CHECK(first[0].status == PointStatus::Done);
    REQUIRE(first[1].status == PointStatus::Failed);
    CHECK_THAT(first[1].error, Catch::Contains("exit code 1: grainlink: error:"));
    CHECK_THAT(first[1].error, Catch::Contains("overlap"));
    CHECK(first[1].log == folder / ("study/points/" + first[1].point.id + ".failed/log.txt"));
    CHECK_THAT(readFile(first[1].log), Catch::Contains("overlap"));
    CHECK_FALSE(fs::exists(folder / ("study/points/" + first[1].point.id)));
    // Its run's time is the run's, not the study machinery's (each point's wall beyond it).
    CHECK(first[1].run_wall_s > 0.0);
    CHECK(first[1].run_wall_s <= first[1].wall_s);

    const std::vector<PointResult> again = run(s, localPool(1, folder));
    CHECK(again[1].status == PointStatus::Failed);
    CHECK_FALSE(again[1].ran_now);
    CHECK_FALSE(again[0].ran_now);
    ExecutorOptions retry = localPool(1, folder);
    retry.retry_failed = true;
    const std::vector<PointResult> retried = run(s, retry);
    CHECK(retried[1].status == PointStatus::Failed);
    CHECK(retried[1].ran_now);
    CHECK_FALSE(retried[0].ran_now);
}

TEST_CASE("a study killed mid-run, started again, runs only the unfinished points and leaves "
          "the finished ones as they were",
          "[study][local]") {
    TempFolder folder("resume");
    writeFile(folder / "six.yaml",
              "name: six\nbase: {kind: dem, scenario: " + kData +
                  "/plate.yaml}\n"
                  "design:\n  vary:\n"
                  "    - {key: bodies.0.motion.0.velocity_m_s, values: [[0, 0, -0.1], "
                  "[0, 0, -0.05]]}\n"
                  "  replicates: 3\nobservables: [bodies.plate.force_N.2]\n");
    const std::vector<std::string> command{
        kGrainlink, "study", folder / "six.yaml", "--out", folder / "study", "--jobs", "1"};
    const fs::path study = folder / "study";
    std::map<std::string, std::map<std::string, std::string>> before; // id: file: bytes
    {
        Process killed(command, folder.path, folder / "killed.log");
        REQUIRE(waitUntil([&] { return finishedPoints(study).size() >= 2; }, 60.0));
        kill(killed.pid(), SIGKILL);
        killed.wait();
    }
    // Its running point's process died with it (nothing is written after the kill).
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const std::vector<std::string> finished = finishedPoints(study);
    REQUIRE(finished.size() < 6);
    for (const std::string &id : finished)
        for (const auto &e : fs::directory_iterator(study / "points" / id))
            before[id][e.path().filename().string()] = readFile(e.path());

    std::string output;
    REQUIRE(runToEnd(command, folder.path.string(), output) == 0);
    INFO(output);
    CHECK_THAT(output, Catch::Contains("6 points: 6 done (" + std::to_string(6 - finished.size()) +
                                       " run now), 0 failed, 0 unfinished"));
    CHECK(finishedPoints(study).size() == 6);
    for (const auto &[id, files] : before)
        for (const auto &[name, bytes] : files) {
            INFO(id << "/" << name);
            CHECK(readFile(study / "points" / id / name) == bytes); // log and wall time too
        }
    for (const auto &e : fs::directory_iterator(study / "points"))
        CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
}

namespace {

/// The child processes of `pid` (every thread's), from /proc.
std::vector<pid_t> childrenOf(pid_t pid) {
    std::vector<pid_t> children;
    const fs::path tasks = "/proc/" + std::to_string(pid) + "/task";
    std::error_code missing;
    for (const auto &task : fs::directory_iterator(tasks, missing)) {
        std::ifstream in(task.path() / "children");
        for (pid_t child; in >> child;)
            children.push_back(child);
    }
    return children;
}

/// The test scenario as folder/plate.yaml with a longer run (the plate rests after 0.12 s), so
/// that its process is there to be killed; `output_keys` are added to its output line.
void writeLongerPlate(const TempFolder &folder, const std::string &duration_s,
                      const std::string &output_keys = "") {
    std::string scenario = readFile(kData + "/plate.yaml");
    const std::string run = "run: {duration_s: 0.12}";
    scenario.replace(scenario.find(run), run.size(), "run: {duration_s: " + duration_s + "}");
    const std::string output = "output: {series_interval_s: 0.01";
    scenario.insert(scenario.find(output) + output.size(), output_keys);
    writeFile(folder / "plate.yaml", scenario);
}

} // namespace

TEST_CASE("a run killed from outside leaves its point unfinished while the study goes on, the "
          "next start runs just that point",
          "[study][local]") {
    TempFolder folder("killed-run");
    writeLongerPlate(folder, "0.8");
    writeFile(folder / "three.yaml", "name: three\nbase: {kind: dem, scenario: plate.yaml}\n"
                                     "design:\n  replicates: 3\n"
                                     "observables: [bodies.plate.force_N.2]\n");
    const std::vector<std::string> command{
        kGrainlink, "study", folder / "three.yaml", "--out", folder / "study", "--jobs", "1"};
    Process study(command, folder.path, folder / "first.log");
    std::vector<pid_t> runs;
    REQUIRE(waitUntil([&] { return !(runs = childrenOf(study.pid())).empty(); }, 30.0));
    REQUIRE(runs.size() == 1);
    kill(runs[0], SIGKILL);
    CHECK(study.wait() == 0); // the others went on; nothing failed
    const std::string first = readFile(folder / "first.log");
    INFO(first);
    CHECK_THAT(first, Catch::Contains("3 points: 2 done (2 run now), 0 failed, 1 unfinished"));
    CHECK_THAT(first, Catch::Contains("interrupted (killed by signal 9"));

    std::string output;
    REQUIRE(runToEnd(command, folder.path.string(), output) == 0);
    CHECK_THAT(output, Catch::Contains("3 points: 3 done (1 run now), 0 failed, 0 unfinished"));
}

TEST_CASE("a point whose run was killed after a checkpoint continues from it, to the result of "
          "an uninterrupted run",
          "[study][local]") {
    TempFolder folder("resumed-point");
    // A few seconds of wall time, with a checkpoint every 0.05 s; one point.
    writeLongerPlate(folder, "3.0", ", checkpoint_interval_s: 0.05");
    writeFile(folder / "one.yaml", "name: one\nbase: {kind: dem, scenario: plate.yaml}\n"
                                   "observables: [bodies.plate.force_N.2]\n");
    const auto command = [&](const std::string &out) {
        return std::vector<std::string>{
            kGrainlink, "study", folder / "one.yaml", "--out", folder / out, "--jobs", "1"};
    };
    std::string whole_output;
    REQUIRE(runToEnd(command("whole"), folder.path.string(), whole_output) == 0);
    const auto whole = finishedPoints(folder.path / "whole");
    REQUIRE(whole.size() == 1);

    // The same point, its run killed once a checkpoint past the first is written.
    Process study(command("broken"), folder.path, folder / "first.log");
    REQUIRE(waitUntil(
        [&] {
            std::error_code none_yet;
            for (const auto &e :
                 fs::directory_iterator(folder.path / "broken" / "points", none_yet))
                if (fs::exists(e.path() / "checkpoint.previous.bin"))
                    return true;
            return false;
        },
        60.0));
    // The run is the study's child now, whatever children it had before (one read before the
    // checkpoint could name another, and the run then went unkilled: a rare failure under load).
    const std::vector<pid_t> runs = childrenOf(study.pid());
    REQUIRE(runs.size() == 1);
    kill(runs[0], SIGKILL);
    CHECK(study.wait() == 0);
    const std::string first = readFile(folder / "first.log");
    INFO(first);
    CHECK_THAT(first, Catch::Contains("rerun the study to finish it from its last checkpoint"));
    CHECK_THAT(first, Catch::Contains("0 failed, 1 unfinished"));

    std::string second;
    REQUIRE(runToEnd(command("broken"), folder.path.string(), second) == 0);
    INFO(second);
    const auto resumed = finishedPoints(folder.path / "broken");
    REQUIRE(resumed == whole);
    const fs::path point = folder.path / "broken" / "points" / resumed[0];
    CHECK_THAT(
        readFile(point / "log.txt"),
        Catch::Contains("[study] continuing from the checkpoint an interrupted attempt left"));
    // Every number of the summary but the wall times is the uninterrupted run's.
    const json a =
        json::parse(readFile(folder.path / "whole" / "points" / whole[0] / "summary.json"));
    const json b = json::parse(readFile(point / "summary.json"));
    const json flat_a = a.flatten(), flat_b = b.flatten();
    REQUIRE(flat_a.size() == flat_b.size());
    for (const auto &[key, value] : flat_a.items()) {
        INFO(key);
        if (key.find("wall") == std::string::npos && key.find("per_s") == std::string::npos)
            CHECK(flat_b.at(key) == value);
    }
    CHECK(readFile(point / "series.csv") ==
          readFile(folder.path / "whole" / "points" / whole[0] / "series.csv"));
}

TEST_CASE("a study of coupled runs collects each rig's steady report", "[study][local]") {
    // `grainlink study` (whose reader of coupled scenarios is the command's) on two coupled
    // wheel runs on the rigid floor (rig, floor, coordinator: three processes each): one steady,
    // whose rig_summary.json the study reads — a torque-driven wheel's motor torque is the set
    // torque, the floor carries the normal load 3 kg x 9.81 m/s^2 within 1 % —, and one whose
    // drive is shorter than its judging needs before the run's end time: the run exits non-zero
    // and its point fails with the rig's message.
    TempFolder folder("coupled");
    writeFile(folder / "wheels.yaml",
              "name: wheels\nbase: {kind: run, scenario: " + kData +
                  "/wheel_floor.yaml}\n"
                  "design:\n  combine: zip\n  vary:\n"
                  "    - {key: rig.drive_torque_N_m, values: [0.1, 0.15]}\n"
                  "    - {key: wheel_test.drive_min_s, values: [0.6, 5.0]}\n"
                  "observables: [motor_torque_N_m.mean, vertical_force_N.mean]\n");
    std::string output;
    const int code = runToEnd({kGrainlink, "study", folder / "wheels.yaml", "--out",
                               folder / "study", "--jobs", "1"},
                              folder.path.string(), output);
    INFO(output);
    CHECK(code != 0); // a point failed
    const auto points = finishedPoints(folder.path / "study");
    REQUIRE(points.size() == 1);
    const auto summary = nlohmann::json::parse(
        readFile(folder.path / "study" / "points" / points[0] / "rig_summary.json"));
    CHECK(summary["steady"] == true);
    CHECK(summary["motor_torque_N_m"]["mean"].get<double>() == Approx(0.1).epsilon(1e-6));
    CHECK(summary["vertical_force_N"]["mean"].get<double>() == Approx(3.0 * 9.81).epsilon(0.01));
    CHECK(summary["vertical_force_N"]["standard_error"].get<double>() > 0.0);
    CHECK_THAT(output, Catch::Contains("2 points: 1 done (2 run now), 1 failed"));
    // The failed point's error is the run's last word: the rig's reason.
    CHECK_THAT(output, Catch::Contains("exit code 1: run: wheel test: no steady state: the run "
                                       "ended at t = 1.5 s"));
}
