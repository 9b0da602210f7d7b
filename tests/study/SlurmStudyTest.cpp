// A study through Slurm, end to end: scripts/slurm-local starts a one-node cluster on this
// machine (munged, slurmctld, slurmd), the study submits one job array, follows it with squeue
// and gets the same point results as the local pool; --submit-only and collect later.
// Registered as its own ctest (tests/study/CMakeLists.txt), skipped only when the daemons
// cannot start here.
#include "StudyFixtures.hpp"

#include "grainlink/study/Design.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <iostream>
#include <map>

using namespace grainlink::study;
using namespace grainlink::study::test;

namespace {

/// The test cluster for the lifetime of the object.
class LocalCluster {
public:
    explicit LocalCluster(const std::string &directory) : directory_(directory) {
        std::string output;
        code_ =
            runToEnd({kSource + "/scripts/slurm-local", "start", directory_}, directory_, output);
        message_ = output;
        if (code_ == 0)
            setenv("SLURM_CONF", (directory_ + "/slurm.conf").c_str(), 1);
    }
    ~LocalCluster() {
        std::string ignored;
        runToEnd({kSource + "/scripts/slurm-local", "stop", directory_}, directory_, ignored);
    }
    int code() const { return code_; }
    const std::string &message() const { return message_; }

private:
    std::string directory_, message_;
    int code_ = -1;
};

ExecutorOptions slurm(const TempFolder &folder) {
    ExecutorOptions options;
    options.executor = ExecutorOptions::Executor::Slurm;
    options.grainlink = kGrainlink;
    options.working_directory = folder.path.string();
    options.slurm.poll_interval_s = 0.5;
    options.slurm.partition = "local";
    options.slurm.time_limit = "00:05:00";
    return options;
}

} // namespace

TEST_CASE("a study through a Slurm job array gives the local pool's results", "[slurm]") {
    TempFolder cluster_folder("slurm-cluster"), through_slurm("slurm"), local("slurm-local"),
        later("slurm-later");
    const LocalCluster cluster(cluster_folder.path.string());
    if (cluster.code() == 77) {
        std::cout << "skipped: cannot start the Slurm test cluster: " << cluster.message();
        return;
    }
    REQUIRE(cluster.code() == 0);

    const Study s = loadStudy(kData + "/sweep.yaml", through_slurm / "study");
    const std::vector<PointResult> queued = run(s, slurm(through_slurm));
    ExecutorOptions pool;
    pool.grainlink = kGrainlink;
    pool.working_directory = local.path.string();
    std::map<std::string, PointResult> by_pool;
    for (const PointResult &r : run(loadStudy(kData + "/sweep.yaml", local / "study"), pool))
        by_pool[r.point.id] = r;
    REQUIRE(queued.size() == 4);
    for (const PointResult &r : queued) {
        INFO(r.point.label << ": " << r.error);
        REQUIRE(r.status == PointStatus::Done);
        CHECK(readFile(r.folder + "/series.csv") ==
              readFile(by_pool.at(r.point.id).folder + "/series.csv"));
        CHECK(withoutWallTime(r.summary) == withoutWallTime(by_pool.at(r.point.id).summary));
    }
    const std::string script = readFile(through_slurm / "study/slurm/array-0.sbatch");
    CHECK_THAT(script, Catch::Contains("#SBATCH --array=0-3\n"));
    CHECK_THAT(script, Catch::Contains("#SBATCH --cpus-per-task=1\n"));
    CHECK_THAT(script, Catch::Contains("#SBATCH --partition=local\n"));

    // Finished points are not submitted again: nothing to run, no second array.
    const std::vector<PointResult> again = run(s, slurm(through_slurm));
    for (const PointResult &r : again)
        CHECK_FALSE(r.ran_now);
    CHECK_FALSE(fs::exists(through_slurm / "study/slurm/array-1.txt"));

    // --submit-only, then collect once the queue is empty.
    ExecutorOptions submit = slurm(later);
    submit.slurm.submit_only = true;
    submit.slurm.max_running = 1;
    const Study s_later = loadStudy(kData + "/sweep.yaml", later / "study");
    for (const PointResult &r : run(s_later, submit))
        CHECK(r.status == PointStatus::Unfinished);
    CHECK_THAT(readFile(later / "study/slurm/array-0.sbatch"),
               Catch::Contains("#SBATCH --array=0-3%1\n"));
    REQUIRE(waitUntil([&] { return finishedPoints(later / "study").size() == 4; }, 120.0));
    std::string output;
    REQUIRE(runToEnd({kGrainlink, "study", "collect", later / "study"}, later.path.string(),
                     output) == 0);
    CHECK_THAT(output, Catch::Contains("4 points: 4 done (0 run now), 0 failed, 0 unfinished"));
    for (const PointResult &r : collect(s_later))
        CHECK(withoutWallTime(r.summary) == withoutWallTime(by_pool.at(r.point.id).summary));
}
