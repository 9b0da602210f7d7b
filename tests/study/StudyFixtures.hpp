#pragma once
// Shared by the study tests: fresh folders, the test scenarios, real `grainlink` processes.
#include "grainlink/study/Study.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char **environ;

namespace grainlink::study::test {

namespace fs = std::filesystem;

inline const std::string kGrainlink = GRAINLINK_EXECUTABLE;
inline const std::string kData = STUDY_TEST_DATA;      // tests/study/data
inline const std::string kSource = PROJECT_SOURCE_DIR; // the repository

/// An empty folder for one test, removed afterwards (the process id keeps runs apart).
struct TempFolder {
    fs::path path;
    explicit TempFolder(const std::string &name)
        : path(fs::temp_directory_path() /
               ("grainlink-study-" + name + "-" + std::to_string(getpid()))) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempFolder() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
    std::string operator/(const std::string &name) const { return (path / name).string(); }
};

inline std::string readFile(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw std::runtime_error("cannot read " + path.string());
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

inline void writeFile(const fs::path &path, const std::string &text) {
    std::ofstream(path) << text;
}

/// The number of times `what` occurs in `text`.
inline int count(const std::string &text, const std::string &what) {
    int n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
        ++n;
    return n;
}

/// A real process started in `directory` with stdout and stderr to `log`.
class Process {
public:
    Process(const std::vector<std::string> &argv, const std::string &directory,
            const std::string &log) {
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addchdir_np(&actions, directory.c_str());
        posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        std::vector<std::string> words = argv;
        std::vector<char *> args;
        for (auto &w : words)
            args.push_back(w.data());
        args.push_back(nullptr);
        if (posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ) != 0)
            throw std::runtime_error("cannot start " + argv[0]);
        posix_spawn_file_actions_destroy(&actions);
    }
    ~Process() {
        if (pid_ > 0) {
            kill(pid_, SIGKILL);
            wait();
        }
    }
    pid_t pid() const { return pid_; }
    /// The exit code (128 + signal when killed).
    int wait() {
        int status = 0;
        waitpid(pid_, &status, 0);
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }

private:
    pid_t pid_ = -1;
};

/// Runs argv to its end; returns its exit code, its output in `output`.
inline int runToEnd(const std::vector<std::string> &argv, const std::string &directory,
                    std::string &output) {
    const std::string log = directory + "/.process-" + std::to_string(getpid()) + ".log";
    Process p(argv, directory, log);
    const int code = p.wait();
    output = readFile(log);
    fs::remove(log);
    return code;
}

/// Waits until `done` holds, up to `limit_s`; false if it never did.
template <class Predicate> bool waitUntil(Predicate done, double limit_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
    while (!done()) {
        if (std::chrono::steady_clock::now() > end)
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
}

/// A summary without its wall time: what must agree between two runs of one point.
inline nlohmann::json withoutWallTime(nlohmann::json summary) {
    summary.erase("wall_s");
    return summary;
}

/// The finished point folders of a study folder (points/ID, no suffix).
inline std::vector<std::string> finishedPoints(const fs::path &study) {
    std::vector<std::string> ids;
    if (!fs::exists(study / "points"))
        return ids;
    for (const auto &e : fs::directory_iterator(study / "points"))
        if (e.is_directory() && e.path().filename().string().find('.') == std::string::npos)
            ids.push_back(e.path().filename().string());
    return ids;
}

} // namespace grainlink::study::test
