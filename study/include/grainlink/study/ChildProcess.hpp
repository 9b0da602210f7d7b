#pragma once
// The processes a study starts: a point's run (output to its log) and the Slurm commands whose
// answer it reads.
#include <sys/types.h>

#include <string>
#include <vector>

namespace grainlink::study {

struct ExitStatus {
    int code = -1;  ///< exit code when it exited
    int signal = 0; ///< the signal that killed it, else 0
    bool ok() const { return signal == 0 && code == 0; }
    /// Killed from outside (SIGKILL, SIGTERM, SIGINT, SIGHUP): unfinished, not failed.
    bool interrupted() const;
    std::string describe() const; ///< "exit code 1", "killed by signal 9 (Killed)"
};

/// Runs `argv` (argv[0] a path or a name on PATH) in `directory` with stdout and stderr
/// appended to `log_path` and OMP_WAIT_POLICY=PASSIVE, and waits for it. The child is killed
/// when the calling thread's process dies, so a killed study leaves no runs behind.
ExitStatus runLogged(const std::vector<std::string> &argv, const std::string &directory,
                     const std::string &log_path);

struct Captured {
    ExitStatus status;
    std::string output; ///< stdout and stderr together
};
/// Runs `argv` and returns what it printed; a program that cannot start gives exit code 127.
Captured capture(const std::vector<std::string> &argv);

} // namespace grainlink::study
