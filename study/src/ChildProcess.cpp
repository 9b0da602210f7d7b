#include "grainlink/study/ChildProcess.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

extern char **environ;

namespace grainlink::study {

namespace {

/// argv and envp as the C arrays exec wants, built before fork (the child may only call
/// async-signal-safe functions: the pool forks from several threads).
struct ExecArguments {
    std::vector<std::string> words, environment;
    std::vector<char *> argv, envp;
    ExecArguments(const std::vector<std::string> &argv_words, bool passive_omp)
        : words(argv_words) {
        for (char **e = environ; *e; ++e)
            if (!passive_omp || std::strncmp(*e, "OMP_WAIT_POLICY=", 16) != 0)
                environment.emplace_back(*e);
        if (passive_omp)
            environment.emplace_back("OMP_WAIT_POLICY=PASSIVE");
        for (auto &w : words)
            argv.push_back(w.data());
        argv.push_back(nullptr);
        for (auto &e : environment)
            envp.push_back(e.data());
        envp.push_back(nullptr);
    }
};

ExitStatus waitFor(pid_t pid) {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
    ExitStatus s;
    if (WIFEXITED(status))
        s.code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        s.signal = WTERMSIG(status);
    return s;
}

} // namespace

bool ExitStatus::interrupted() const {
    return signal == SIGKILL || signal == SIGTERM || signal == SIGINT || signal == SIGHUP;
}

std::string ExitStatus::describe() const {
    if (signal)
        return "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
    return "exit code " + std::to_string(code);
}

ExitStatus runLogged(const std::vector<std::string> &argv, const std::string &directory,
                     const std::string &log_path) {
    ExecArguments exec(argv, true);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0)
        throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    if (pid == 0) {
        // PR_SET_PDEATHSIG fires when the forking thread ends: the pool's threads wait for
        // their child, so that is when the study itself dies.
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent)
            _exit(127);
        const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (log < 0 || dup2(log, 1) < 0 || dup2(log, 2) < 0)
            _exit(126);
        if (log > 2)
            close(log);
        const int null = open("/dev/null", O_RDONLY);
        if (null >= 0)
            dup2(null, 0);
        if (!directory.empty() && chdir(directory.c_str()) != 0)
            _exit(126);
        execvpe(exec.argv[0], exec.argv.data(), exec.envp.data());
        _exit(127);
    }
    return waitFor(pid);
}

Captured capture(const std::vector<std::string> &argv) {
    ExecArguments exec(argv, false);
    int pipe_ends[2];
    if (pipe2(pipe_ends, O_CLOEXEC) != 0)
        throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    const pid_t pid = fork();
    if (pid < 0)
        throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    if (pid == 0) {
        dup2(pipe_ends[1], 1);
        dup2(pipe_ends[1], 2);
        execvpe(exec.argv[0], exec.argv.data(), exec.envp.data());
        _exit(127);
    }
    close(pipe_ends[1]);
    Captured c;
    char buffer[4096];
    for (ssize_t n; (n = read(pipe_ends[0], buffer, sizeof buffer)) != 0;) {
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            break;
        c.output.append(buffer, std::size_t(n));
    }
    close(pipe_ends[0]);
    c.status = waitFor(pid);
    return c;
}

} // namespace grainlink::study
