#pragma once
// The participant processes `grainlink run` starts: spawned with posix_spawn, watched from a
// thread so a crash is reported at once (with its exit status), and ended with the run.
#include <sys/types.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace grainlink::apps {

class ChildProcesses {
public:
    /// Called once per child that ends before stopAll(): its name and how it ended.
    using OnExit = std::function<void(const std::string &name, const std::string &how)>;

    explicit ChildProcesses(OnExit on_unexpected_exit);
    ~ChildProcesses();

    /// Starts `argv` (program found on PATH, with this executable's folder searched first).
    void start(const std::string &name, const std::vector<std::string> &argv);
    /// Waits up to `grace_s` for every child to exit by itself, then kills the rest.
    /// Returns the names of children that ended with a failure.
    std::vector<std::string> stopAll(double grace_s);

private:
    struct Child {
        std::string name;
        pid_t pid;
        bool done = false;
        int status = 0;
    };
    void watch();
    std::string describe(int status) const;

    OnExit on_exit_;
    std::mutex mutex_;
    std::vector<Child> children_;
    std::atomic<bool> stopping_{false};
    std::atomic<bool> quit_{false};
    std::thread watcher_;
};

} // namespace grainlink::apps
