#include "ChildProcesses.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

extern char **environ;

namespace grainlink::apps {

namespace {

/// The running executable's path (empty if it cannot be read).
std::string ownExecutable() {
    char path[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", path, sizeof path - 1);
    return n > 0 ? std::string(path, static_cast<std::size_t>(n)) : std::string();
}

/// The folder of the running executable, so programs built beside `grainlink` are found first.
std::string ownFolder() {
    const std::string s = ownExecutable();
    return s.empty() ? s : s.substr(0, s.rfind('/'));
}

} // namespace

ChildProcesses::ChildProcesses(OnExit on_unexpected_exit)
    : on_exit_(std::move(on_unexpected_exit)), watcher_([this] { watch(); }) {
    const char *path = std::getenv("PATH");
    const std::string folder = ownFolder();
    if (!folder.empty())
        ::setenv("PATH", (folder + ":" + (path ? path : "/usr/bin:/bin")).c_str(), 1);
    // The participants share the cores with each other and the coordinator, which wake every
    // window: spinning OpenMP barriers would steal their time (unless the user chose otherwise).
    ::setenv("OMP_WAIT_POLICY", "PASSIVE", 0);
}

ChildProcesses::~ChildProcesses() {
    stopAll(0.0);
    quit_ = true;
    if (watcher_.joinable())
        watcher_.join();
}

void ChildProcesses::start(const std::string &name, const std::vector<std::string> &argv) {
    std::vector<char *> args;
    for (const auto &a : argv)
        args.push_back(const_cast<char *>(a.c_str()));
    args.push_back(nullptr);
    // Each child in its own process group: Ctrl-C in the terminal reaches only `grainlink`,
    // which then stops the run in order (participants told, files closed) instead of every
    // process dying at once.
    posix_spawnattr_t attributes;
    ::posix_spawnattr_init(&attributes);
    ::posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    ::posix_spawnattr_setpgroup(&attributes, 0);
    // A participant that is `grainlink` runs this very executable: a copy under another name,
    // or another grainlink first on PATH, must not run the nodes of a different version.
    const std::string self = argv[0] == "grainlink" ? ownExecutable() : std::string();
    pid_t pid = 0;
    const int error =
        self.empty()
            ? ::posix_spawnp(&pid, args[0], nullptr, &attributes, args.data(), environ)
            : ::posix_spawn(&pid, self.c_str(), nullptr, &attributes, args.data(), environ);
    ::posix_spawnattr_destroy(&attributes);
    if (error != 0)
        throw std::runtime_error("cannot start participant '" + name + "' (" + argv[0] +
                                 "): " + std::strerror(error));
    std::lock_guard<std::mutex> lock(mutex_);
    children_.push_back(Child{name, pid});
}

std::string ChildProcesses::describe(int status) const {
    if (WIFEXITED(status))
        return "exited with status " + std::to_string(WEXITSTATUS(status));
    if (WIFSIGNALED(status))
        return std::string("was killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
               ::strsignal(WTERMSIG(status)) + ")";
    return "ended";
}

void ChildProcesses::watch() {
    while (!quit_) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        std::lock_guard<std::mutex> lock(mutex_);
        for (auto &c : children_) {
            if (c.done)
                continue;
            int status = 0;
            if (::waitpid(c.pid, &status, WNOHANG) == c.pid) {
                c.done = true;
                c.status = status;
                const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
                if (!stopping_ && !clean)
                    on_exit_(c.name, describe(status));
            }
        }
    }
}

std::vector<std::string> ChildProcesses::stopAll(double grace_s) {
    stopping_ = true;
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            bool all_done = true;
            for (auto &c : children_) {
                if (!c.done && ::waitpid(c.pid, &c.status, WNOHANG) == c.pid)
                    c.done = true;
                all_done = all_done && c.done;
            }
            const double waited =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (all_done || waited >= grace_s) {
                std::vector<std::string> failed;
                for (auto &c : children_) {
                    if (!c.done) {
                        ::kill(c.pid, SIGKILL);
                        ::waitpid(c.pid, &c.status, 0);
                        c.done = true;
                        failed.push_back(c.name + " (killed after the run)");
                    } else if (!(WIFEXITED(c.status) && WEXITSTATUS(c.status) == 0)) {
                        failed.push_back(c.name + " " + describe(c.status));
                    }
                }
                children_.clear();
                return failed;
            }
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

} // namespace grainlink::apps
