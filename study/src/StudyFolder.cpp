#include "grainlink/study/StudyFolder.hpp"

#include "grainlink/study/ChildProcess.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace grainlink::study {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string readText(const fs::path &path) {
    std::ifstream in(path);
    if (!in)
        throw std::runtime_error("cannot read '" + path.string() + "'");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The line of a run's log that says why it failed: its last error line, else its last line.
std::string reasonIn(const fs::path &log) {
    std::ifstream in(log);
    std::string line, last, error;
    while (std::getline(in, line)) {
        if (line.empty())
            continue;
        last = line;
        if (line.find("error") != std::string::npos)
            error = line;
    }
    return error.empty() ? last : error;
}

/// An exclusive flock on a point's lock file, released when the holder ends, however it ends.
class PointLock {
public:
    explicit PointLock(const std::string &path)
        : fd_(open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) {
        if (fd_ < 0)
            throw std::runtime_error("cannot open lock file '" + path + "'");
        held_ = flock(fd_, LOCK_EX | LOCK_NB) == 0;
    }
    ~PointLock() { close(fd_); }
    PointLock(const PointLock &) = delete;
    PointLock &operator=(const PointLock &) = delete;
    bool held() const { return held_; }

private:
    int fd_;
    bool held_ = false;
};

json kindJson(const Kind &k) {
    return {{"name", k.name},
            {"command", k.command},
            {"summary_file", k.summary_file},
            {"threads_key", k.threads_key},
            {"seed_key", k.seed_key},
            {"checkpoint_file", k.checkpoint_file}};
}

Kind kindFrom(const json &j) {
    Kind k;
    k.name = j.at("name").get<std::string>();
    k.command = j.at("command").get<std::vector<std::string>>();
    k.summary_file = j.at("summary_file").get<std::string>();
    k.threads_key = j.at("threads_key").get<std::string>();
    k.seed_key = j.at("seed_key").get<std::string>();
    // A study folder written before points resumed has none: its points start again.
    k.checkpoint_file = j.value("checkpoint_file", std::string());
    return k;
}

void appendToLog(const std::string &path, const std::string &line) {
    std::ofstream out(path, std::ios::app);
    out << line;
}

} // namespace

void writeFileAtomically(const std::string &path, const std::string &text) {
    const std::string temporary = path + ".tmp-" + std::to_string(getpid());
    {
        std::ofstream out(temporary, std::ios::trunc);
        out << text;
        if (!out)
            throw std::runtime_error("cannot write '" + temporary + "'");
    }
    fs::rename(temporary, path);
}

StudyFolder::StudyFolder(std::string directory)
    : directory_(fs::absolute(directory).lexically_normal().string()) {}

std::string StudyFolder::scenarioPath(const Point &p) const {
    return directory_ + "/scenarios/" + p.id + ".yaml";
}
std::string StudyFolder::pointPath(const Point &p) const {
    return directory_ + "/points/" + p.id;
}
std::string StudyFolder::failedPath(const Point &p) const {
    return pointPath(p) + ".failed";
}
std::string StudyFolder::slurmPath() const {
    return directory_ + "/slurm";
}

void StudyFolder::write(const Study &study) const {
    fs::create_directories(directory_ + "/scenarios");
    fs::create_directories(directory_ + "/points");
    json points = json::array();
    for (const Point &p : study.points) {
        const std::string path = scenarioPath(p);
        if (!fs::exists(path) || readText(path) != p.scenario_yaml)
            writeFileAtomically(path, p.scenario_yaml);
        points.push_back({{"id", p.id},
                          {"label", p.label},
                          {"origin", p.origin},
                          {"kind", kindJson(p.kind)},
                          {"threads", p.threads},
                          {"settings", p.settings}});
    }
    const json j = {{"format", 1},
                    {"name", study.name},
                    {"source", study.source},
                    {"observables", study.observables},
                    {"varied_keys", study.varied_keys},
                    {"replicate_key", study.replicate_key},
                    {"points", points}};
    writeFileAtomically(directory_ + "/study.json", j.dump(2) + "\n");
}

Study StudyFolder::read() const {
    const std::string path = directory_ + "/study.json";
    if (!fs::exists(path))
        throw std::runtime_error("'" + directory_ + "' is not a study folder (no study.json)");
    const json j = json::parse(readText(path));
    Study s;
    s.directory = directory_;
    s.name = j.at("name").get<std::string>();
    s.source = j.at("source").get<std::string>();
    s.observables = j.at("observables").get<std::vector<std::string>>();
    s.varied_keys = j.at("varied_keys").get<std::vector<std::string>>();
    s.replicate_key = j.at("replicate_key").get<std::string>();
    for (const json &e : j.at("points")) {
        Point p;
        p.id = e.at("id").get<std::string>();
        p.label = e.at("label").get<std::string>();
        p.origin = e.at("origin").get<std::string>();
        p.kind = kindFrom(e.at("kind"));
        p.threads = e.at("threads").get<int>();
        p.settings = e.at("settings").get<std::vector<std::pair<std::string, std::string>>>();
        p.scenario_yaml = readText(scenarioPath(p));
        s.points.push_back(std::move(p));
    }
    return s;
}

PointResult StudyFolder::state(const Point &point) const {
    PointResult r;
    r.point = point;
    const fs::path done = pointPath(point), failed = failedPath(point);
    if (fs::exists(done)) {
        r.status = PointStatus::Done;
        r.folder = done.string();
        r.log = (done / "log.txt").string();
        r.summary = json::parse(readText(done / point.kind.summary_file));
        const json info = json::parse(readText(done / "point.json"));
        r.wall_s = info.at("wall_s").get<double>();
        const auto wall = r.summary.find("wall_s");
        r.run_wall_s =
            wall != r.summary.end() && wall->is_number() ? wall->get<double>() : r.wall_s;
    } else if (fs::exists(failed)) {
        r.status = PointStatus::Failed;
        r.folder = failed.string();
        r.log = (failed / "log.txt").string();
        r.error = readText(failed / "error.txt");
        while (!r.error.empty() && r.error.back() == '\n')
            r.error.pop_back();
    } else {
        r.status = PointStatus::Unfinished;
        r.error = "not run yet";
    }
    return r;
}

PointResult StudyFolder::runPoint(const Point &point, const std::string &grainlink,
                                  const std::string &directory, bool retry_failed) const {
    const auto start = std::chrono::steady_clock::now();
    fs::create_directories(directory_ + "/points");
    const PointLock lock(pointPath(point) + ".lock");
    if (!lock.held()) {
        PointResult busy = state(point);
        busy.error = "being run by another process";
        return busy;
    }
    PointResult r = state(point);
    if (!runsAgain(r, retry_failed))
        return r;
    fs::remove_all(failedPath(point));
    r = PointResult();
    r.point = point;
    // Leftovers of runs whose process died: nobody else runs this point while we hold the lock.
    // The newest that holds a checkpoint is continued with the run's own --resume (which gives
    // the uninterrupted run's results); the others are removed.
    const std::string stem = point.id + ".tmp-";
    const std::string &checkpoint = point.kind.checkpoint_file;
    std::vector<fs::path> leftovers;
    for (const auto &entry : fs::directory_iterator(directory_ + "/points"))
        if (entry.path().filename().string().rfind(stem, 0) == 0)
            leftovers.push_back(entry.path());
    std::optional<fs::path> resumable;
    for (const fs::path &left : leftovers)
        if (!checkpoint.empty() && fs::exists(left / checkpoint) &&
            (!resumable ||
             fs::last_write_time(left / checkpoint) > fs::last_write_time(*resumable / checkpoint)))
            resumable = left;
    for (const fs::path &left : leftovers)
        if (left != resumable)
            fs::remove_all(left);

    const fs::path tmp = pointPath(point) + ".tmp-" + std::to_string(getpid());
    if (resumable)
        fs::rename(*resumable, tmp);
    fs::create_directories(tmp);
    r.log = (tmp / "log.txt").string();
    std::vector<std::string> argv{grainlink};
    argv.insert(argv.end(), point.kind.command.begin(), point.kind.command.end());
    argv.insert(argv.end(), {scenarioPath(point), "--out", tmp.string()});
    if (resumable) {
        argv.push_back("--resume");
        appendToLog(r.log, "[study] continuing from the checkpoint an interrupted attempt left\n");
    }
    const auto run_start = std::chrono::steady_clock::now();
    const ExitStatus exit = runLogged(argv, directory, r.log);
    const double process_s = secondsSince(run_start);
    r.ran_now = true;

    std::string problem;
    if (exit.ok()) {
        const fs::path summary = tmp / point.kind.summary_file;
        try {
            r.summary = json::parse(readText(summary));
        } catch (const std::exception &e) {
            problem = "the run ended but its summary is unreadable: " + std::string(e.what());
        }
    } else if (exit.interrupted()) {
        // Kept when it holds a checkpoint: the next start continues from there.
        const bool kept = !checkpoint.empty() && fs::exists(tmp / checkpoint);
        if (!kept) {
            fs::remove_all(tmp);
            r.log.clear();
        }
        r.status = PointStatus::Unfinished;
        r.error = "interrupted (" + exit.describe() + "); rerun the study to finish it" +
                  (kept ? " from its last checkpoint" : "");
        return r;
    } else {
        problem = exit.describe() + ": " + reasonIn(r.log);
    }
    if (!problem.empty()) {
        writeFileAtomically((tmp / "error.txt").string(), problem + "\n");
        fs::rename(tmp, failedPath(point));
        r.status = PointStatus::Failed;
        r.folder = failedPath(point);
        r.log = r.folder + "/log.txt";
        r.error = problem;
        r.run_wall_s = process_s; // else the machinery counted it (286 s a point, a slope study)
        r.wall_s = secondsSince(start);
        return r;
    }
    const auto wall = r.summary.find("wall_s");
    r.run_wall_s = wall != r.summary.end() && wall->is_number() ? wall->get<double>() : process_s;
    // The study's own time for the point: everything but the run itself, and the rename.
    r.wall_s = secondsSince(start);
    const json info = {{"id", point.id},
                       {"label", point.label},
                       {"kind", point.kind.name},
                       {"settings", point.settings},
                       {"wall_s", r.wall_s}};
    writeFileAtomically((tmp / "point.json").string(), info.dump(2) + "\n");
    fs::rename(tmp, pointPath(point));
    r.status = PointStatus::Done;
    r.folder = pointPath(point);
    r.log = r.folder + "/log.txt";
    return r;
}

} // namespace grainlink::study
