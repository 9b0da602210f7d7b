// coupling_bench: wall time of one coupling window with 6 coupled bodies, real processes.
//
// The parent process runs grainlink::coupling::Coordinator and starts two participants by
// fork+exec of this same binary with the role `participant`: a multibody side that provides
// wheel0..wheel5 and a soil side that consumes them. Neither does physics (each answers at once
// with trivially updated states or wrenches), so every microsecond measured is coupling cost:
// ZeroMQ, protobuf, the participant library and the coordinator. Cases: ipc:// and
// tcp://127.0.0.1, explicit serial and explicit parallel coupling.
//
// What is measured (bench/coupling/README.md):
//   window wall time   multibody participant's clock, from one window's AdvanceTo being handed to
//                      it (waitForCommand() returns) to the next one's: one full coupling period as
//                      the physics side sees it (CLOCK_MONOTONIC, shared by all processes).
//   participants held  from waitForCommand() returning to advance() returning (its "physics",
//                      writeOutputs() checks, encode, send); both sides' intervals, their union
//                      when they overlap (parallel).
//   overhead           window wall time minus that union: the critical-path time in which no
//                      participant holds the window, i.e. the coordinator's code plus ZeroMQ hops.
//                      On a shared CPU a participant's interval also holds whatever the scheduler
//                      ran meanwhile, so the CPU columns are the cleaner split.
//   csv wall_s         the coordinator's own wall_s column (cross-check; excludes the CSV append).
//   CPU                user+system CPU per window of each process, all its threads, whole run.
//   one CPU            share of windows in which both participants ran on the same CPU.
//
// `--floor` adds the same message pattern over bare ZeroMQ (ROUTER/DEALER, payloads of the
// sizes the protocol sends, no protobuf, no checks): the transport's share of a window.
//
// Figures only: nothing here asserts on time.
#include "grainlink/coupling/Coordinator.hpp"
#include "grainlink/coupling/Participant.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <zmq.hpp>

#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace grainlink;

constexpr int kBodies = 6;
constexpr double kTargetMedian_us = 100.0; ///< [µs] the issue's target for the ipc median
constexpr double kMacroStep_s = 1e-3;      ///< [s] window length (irrelevant to the wall time)

std::int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

/// One window as a participant saw it (CLOCK_MONOTONIC, comparable between processes).
struct Stamp {
    std::uint64_t window = 0;
    std::int64_t opened_ns = 0;   ///< waitForCommand() returned Advance
    std::int64_t computed_ns = 0; ///< outputs ready (the "physics" is done)
    std::int64_t sent_ns = 0;     ///< advance() returned
    std::int32_t cpu = -1;        ///< the CPU it ran on when the window opened
};

std::string bodyName(int b) {
    return "wheel" + std::to_string(b);
}

// ------------------------------------------------------------------ participant processes

coupling::ParticipantConfig participantConfig(coupling::Role role, const std::string &endpoint) {
    coupling::ParticipantConfig c;
    c.name = role == coupling::Role::Multibody ? "multibody" : "soil";
    c.role = role;
    c.endpoint = endpoint;
    for (int b = 0; b < kBodies; ++b) {
        if (role == coupling::Role::Soil) {
            c.consumes.push_back(bodyName(b));
            continue;
        }
        coupling::BodyDescription body;
        body.name = bodyName(b);
        body.mass.mass_kg = 5.0;
        body.mass.inertia_diagonal_kg_m2 = coupling::Vec3(0.05, 0.08, 0.05);
        coupling::WheelShape wheel;
        wheel.diameter_m = 0.3;
        wheel.width_m = 0.1;
        wheel.grouser_count = 12;
        wheel.grouser_height_m = 0.01;
        wheel.grouser_thickness_m = 0.004;
        body.geometry = wheel;
        c.provides.push_back(body);
        coupling::BodyState state;
        state.body = body.name;
        state.position_m = coupling::Vec3(0.5 * (b / 2), 0.4 * (b % 2), 0.15);
        state.orientation = coupling::Quat(Eigen::AngleAxisd(0.1 * b, coupling::Vec3::UnitY()));
        state.linear_velocity_m_s = coupling::Vec3(0.1, 0.0, -0.001);
        state.angular_velocity_rad_s = coupling::Vec3(0.0, 0.67, 0.0);
        c.initial_states.push_back(state);
    }
    return c;
}

/// The whole participant: answers every window at once and records when it held it.
int runParticipant(const std::string &role_name, const std::string &endpoint,
                   const std::string &stamps_path) {
    const auto role = role_name == "multibody" ? coupling::Role::Multibody : coupling::Role::Soil;
    const auto config = participantConfig(role, endpoint);
    coupling::Participant participant(config);
    participant.initialize();
    std::vector<coupling::BodyState> states = config.initial_states;
    std::vector<Stamp> stamps;
    stamps.reserve(1 << 16);
    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::Advance: {
            Stamp stamp;
            stamp.opened_ns = now_ns();
            stamp.cpu = sched_getcpu();
            const auto &in = participant.inputs();
            stamp.window = in.window;
            coupling::WindowOutputs out;
            if (role == coupling::Role::Multibody) {
                for (auto &s : states) // drift: the trivial "physics" of this benchmark
                    s.position_m += s.linear_velocity_m_s * in.duration_s;
                out.states = states;
            } else {
                for (const auto &s : in.end_states) {
                    coupling::Wrench w;
                    w.body = s.body;
                    w.force_N = coupling::Vec3(-1.0, 0.0, 50.0 - 1e3 * s.position_m.z());
                    w.torque_N_m = coupling::Vec3(0.0, -0.2, 0.0);
                    out.wrenches.push_back(std::move(w));
                }
            }
            stamp.computed_ns = now_ns();
            participant.writeOutputs(std::move(out));
            participant.advance();
            stamp.sent_ns = now_ns();
            stamps.push_back(stamp);
            break;
        }
        case coupling::Command::WriteCheckpoint:
            participant.checkpointWritten(); // never asked for: checkpoint_every_windows = 0
            break;
        case coupling::Command::Finish: {
            participant.finalize();
            std::ofstream file(stamps_path, std::ios::binary | std::ios::trunc);
            file.write(reinterpret_cast<const char *>(stamps.data()),
                       static_cast<std::streamsize>(stamps.size() * sizeof(Stamp)));
            if (!file.flush())
                throw std::runtime_error("cannot write " + stamps_path);
            return 0;
        }
        }
    }
}

/// Floor participant: a bare DEALER that answers every message with `reply_bytes` bytes.
int runFloorParticipant(const std::string &name, const std::string &endpoint,
                        std::size_t reply_bytes) {
    zmq::context_t context(1);
    zmq::socket_t socket(context, zmq::socket_type::dealer);
    socket.set(zmq::sockopt::routing_id, name);
    socket.set(zmq::sockopt::linger, 0);
    socket.connect(endpoint);
    const std::string reply(reply_bytes, 'x');
    socket.send(zmq::str_buffer("ready"), zmq::send_flags::none);
    for (;;) {
        zmq::message_t message;
        (void)socket.recv(message, zmq::recv_flags::none);
        if (message.size() == 0)
            return 0; // the parent's "stop"
        socket.send(zmq::buffer(reply), zmq::send_flags::none);
    }
}

// ------------------------------------------------------------------ child processes

struct Child {
    pid_t pid = -1;
    std::string name;
    rusage usage{};
};

/// This executable's path, so children show up as coupling_bench in ps and perf.
std::string selfPath() {
    std::string path(4096, '\0');
    const ssize_t n = readlink("/proc/self/exe", path.data(), path.size() - 1);
    if (n <= 0)
        throw std::runtime_error("cannot read /proc/self/exe");
    path.resize(std::size_t(n));
    return path;
}

Child spawn(const std::string &name, const std::vector<std::string> &args) {
    static const std::string self = selfPath();
    std::vector<std::string> full{"coupling_bench"};
    full.insert(full.end(), args.begin(), args.end());
    std::vector<char *> argv;
    for (auto &a : full)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    const pid_t pid = fork();
    if (pid < 0)
        throw std::runtime_error("fork failed for the " + name + " participant");
    if (pid == 0) {
        execv(self.c_str(), argv.data());
        _exit(127);
    }
    return Child{pid, name, {}};
}

/// Waits for the child and keeps its resource usage; throws if it did not exit cleanly.
void reap(Child &child) {
    int status = 0;
    if (wait4(child.pid, &status, 0, &child.usage) != child.pid)
        throw std::runtime_error("lost the " + child.name + " participant");
    child.pid = -1;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw std::runtime_error("the " + child.name + " participant exited with status " +
                                 std::to_string(status));
}

/// Stops children still running after a failure (by their own pid only).
void killAll(std::vector<Child> &children) {
    for (auto &c : children)
        if (c.pid > 0) {
            kill(c.pid, SIGKILL);
            waitpid(c.pid, nullptr, 0);
            c.pid = -1;
        }
}

double cpuSeconds(const rusage &u) {
    return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double switches(const rusage &u) {
    return double(u.ru_nvcsw + u.ru_nivcsw);
}

rusage selfUsage() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u;
}

rusage minus(const rusage &a, const rusage &b) {
    rusage d{};
    const auto us = [](const timeval &t) { return t.tv_sec * 1000000L + t.tv_usec; };
    const auto tv = [](long v) { return timeval{v / 1000000L, v % 1000000L}; };
    d.ru_utime = tv(us(a.ru_utime) - us(b.ru_utime));
    d.ru_stime = tv(us(a.ru_stime) - us(b.ru_stime));
    d.ru_nvcsw = a.ru_nvcsw - b.ru_nvcsw;
    d.ru_nivcsw = a.ru_nivcsw - b.ru_nivcsw;
    return d;
}

// ------------------------------------------------------------------ statistics

/// Nearest-rank percentile of `values` (copied, then partially sorted).
double percentile(std::vector<double> values, double p) {
    if (values.empty())
        return std::nan("");
    const auto rank = static_cast<std::size_t>(std::ceil(p * double(values.size())));
    const std::size_t k = std::min(values.size() - 1, rank > 0 ? rank - 1 : 0);
    std::nth_element(values.begin(), values.begin() + long(k), values.end());
    return values[k];
}

/// One run of one case: per-window figures in µs plus totals.
struct Sample {
    std::vector<double> wall_us, participants_us, overhead_us, csv_wall_us;
    double windows_per_s = 0.0;
    double coordinator_cpu_us = 0.0, multibody_cpu_us = 0.0, soil_cpu_us = 0.0; ///< per window
    double switches_per_window = 0.0; ///< context switches of all three processes
    double same_cpu_percent = -1.0;   ///< windows in which both participants ran on one CPU
};

std::vector<Stamp> readStamps(const std::string &path) {
    std::ifstream file(path, std::ios::binary);
    std::vector<Stamp> stamps;
    Stamp s;
    while (file.read(reinterpret_cast<char *>(&s), sizeof s))
        stamps.push_back(s);
    return stamps;
}

/// Length of the union of two intervals.
double unionLength(double a0, double a1, double b0, double b1) {
    const double overlap = std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
    return (a1 - a0) + (b1 - b0) - overlap;
}

/// wall_s per window from coupling.csv (column "wall_s"), for windows in [first, last).
std::vector<double> csvWallTimes_us(const std::string &path, std::uint64_t first,
                                    std::uint64_t last) {
    std::ifstream in(path);
    std::string line;
    if (!std::getline(in, line))
        throw std::runtime_error(path + " is empty");
    std::size_t column = 0, position = 0;
    for (;;) {
        const auto comma = line.find(',', position);
        if (line.substr(position, comma - position) == "wall_s")
            break;
        if (comma == std::string::npos)
            throw std::runtime_error(path + " has no wall_s column");
        position = comma + 1;
        ++column;
    }
    std::vector<double> out;
    while (std::getline(in, line)) {
        const auto window = std::stoull(line.substr(0, line.find(',')));
        if (window < first || window >= last)
            continue;
        std::size_t start = 0;
        for (std::size_t c = 0; c < column; ++c)
            start = line.find(',', start) + 1;
        out.push_back(1e6 * std::stod(line.substr(start, line.find(',', start) - start)));
    }
    return out;
}

// ------------------------------------------------------------------ cases

struct Case {
    std::string transport; ///< "ipc" or "tcp"
    coupling::SchemeKind scheme = coupling::SchemeKind::ExplicitSerial;
    bool floor = false; ///< bare ZeroMQ instead of the coordinator
};

std::string schemeLabel(const Case &c) {
    return c.scheme == coupling::SchemeKind::ExplicitSerial ? "serial" : "parallel";
}

struct Settings {
    std::uint64_t windows = 20000;
    std::uint64_t warmup = 1000;
    bool csv = true;
    std::string work;
};

std::string endpointFor(const Case &c, const std::string &directory) {
    return c.transport == "ipc" ? "ipc://" + directory + "/coordinator.sock"
                                : std::string("tcp://127.0.0.1:*");
}

Sample runCoupled(const Case &c, const Settings &settings, const std::string &directory) {
    const std::uint64_t total = settings.warmup + settings.windows + 1; // +1: the last period's end
    coupling::CoordinatorConfig config;
    config.endpoint = endpointFor(c, directory);
    config.participants = {{"multibody", coupling::Role::Multibody, {}, true},
                           {"soil", coupling::Role::Soil, {}, true}};
    config.scheme.kind = c.scheme;
    config.macro_step_s = kMacroStep_s;
    config.end_time_s = double(total) * kMacroStep_s;
    config.handshake_timeout_s = 30.0;
    if (settings.csv)
        config.output_directory = directory + "/output";

    coupling::Coordinator coordinator(config);
    const std::string endpoint = coordinator.boundEndpoint();
    const std::string mb_stamps = directory + "/multibody.stamps";
    const std::string soil_stamps = directory + "/soil.stamps";
    std::vector<Child> children;
    const rusage before = selfUsage();
    try {
        children.push_back(spawn("multibody", {"participant", "multibody", endpoint, mb_stamps}));
        children.push_back(spawn("soil", {"participant", "soil", endpoint, soil_stamps}));
        const auto summary = coordinator.run();
        if (summary.windows != total)
            throw std::runtime_error("the coordinator ran " + std::to_string(summary.windows) +
                                     " windows, expected " + std::to_string(total));
        for (auto &child : children)
            reap(child);
    } catch (...) {
        killAll(children);
        throw;
    }
    const rusage coordinator_usage = minus(selfUsage(), before);

    const auto mb = readStamps(mb_stamps), soil = readStamps(soil_stamps);
    if (mb.size() != total || soil.size() != total)
        throw std::runtime_error("participants recorded " + std::to_string(mb.size()) + " and " +
                                 std::to_string(soil.size()) + " windows, expected " +
                                 std::to_string(total));
    Sample s;
    std::uint64_t same_cpu = 0;
    for (std::uint64_t w = settings.warmup; w + 1 < total; ++w) {
        const double wall = double(mb[w + 1].opened_ns - mb[w].opened_ns);
        const double held = unionLength(double(mb[w].opened_ns), double(mb[w].sent_ns),
                                        double(soil[w].opened_ns), double(soil[w].sent_ns));
        s.wall_us.push_back(1e-3 * wall);
        s.participants_us.push_back(1e-3 * held);
        s.overhead_us.push_back(1e-3 * (wall - held));
        same_cpu += mb[w].cpu == soil[w].cpu ? 1 : 0;
    }
    s.same_cpu_percent = 100.0 * double(same_cpu) / double(settings.windows);
    const double span_s = 1e-9 * double(mb[total - 1].opened_ns - mb[settings.warmup].opened_ns);
    s.windows_per_s = double(settings.windows) / span_s;
    s.coordinator_cpu_us = 1e6 * cpuSeconds(coordinator_usage) / double(total);
    s.multibody_cpu_us = 1e6 * cpuSeconds(children[0].usage) / double(total);
    s.soil_cpu_us = 1e6 * cpuSeconds(children[1].usage) / double(total);
    s.switches_per_window =
        (switches(coordinator_usage) + switches(children[0].usage) + switches(children[1].usage)) /
        double(total);
    if (settings.csv)
        s.csv_wall_us =
            csvWallTimes_us(directory + "/output/coupling.csv", settings.warmup, total - 1);
    return s;
}

/// Message sizes [bytes] of one window of this benchmark's 6 bodies as the protocol encodes them
/// (read off the ipc socket writes with strace): AdvanceTo with wrenches, WindowDone with states,
/// AdvanceTo with start and end states, WindowDone with wrenches.
constexpr std::size_t kToMultibody = 310, kFromMultibody = 555, kToSoil = 1085, kFromSoil = 300;

Sample runFloor(const Case &c, const Settings &settings, const std::string &directory) {
    const std::uint64_t total = settings.warmup + settings.windows;
    zmq::context_t context(1);
    zmq::socket_t router(context, zmq::socket_type::router);
    router.set(zmq::sockopt::router_mandatory, 1);
    router.set(zmq::sockopt::linger, 0);
    router.bind(endpointFor(c, directory));
    const std::string endpoint = router.get(zmq::sockopt::last_endpoint);
    std::vector<Child> children;
    const rusage before = selfUsage();
    Sample s;
    try {
        children.push_back(spawn("multibody", {"floor-participant", "multibody", endpoint,
                                               std::to_string(kFromMultibody)}));
        children.push_back(
            spawn("soil", {"floor-participant", "soil", endpoint, std::to_string(kFromSoil)}));
        for (int ready = 0; ready < 2; ++ready) {
            zmq::message_t id, body;
            (void)router.recv(id, zmq::recv_flags::none);
            (void)router.recv(body, zmq::recv_flags::none);
        }
        const std::string to_mb(kToMultibody, 'a'), to_soil(kToSoil, 'b');
        const auto send = [&](const char *peer, const std::string &bytes) {
            router.send(zmq::buffer(std::string(peer)), zmq::send_flags::sndmore);
            router.send(zmq::buffer(bytes), zmq::send_flags::none);
        };
        const auto receive = [&] {
            zmq::message_t id, body;
            (void)router.recv(id, zmq::recv_flags::none);
            (void)router.recv(body, zmq::recv_flags::none);
        };
        std::int64_t measured_from = 0;
        for (std::uint64_t w = 0; w < total; ++w) {
            const std::int64_t start = now_ns();
            if (w == settings.warmup)
                measured_from = start;
            if (c.scheme == coupling::SchemeKind::ExplicitSerial) {
                send("multibody", to_mb);
                receive();
                send("soil", to_soil);
                receive();
            } else {
                send("multibody", to_mb);
                send("soil", to_soil);
                receive();
                receive();
            }
            if (w >= settings.warmup)
                s.wall_us.push_back(1e-3 * double(now_ns() - start));
        }
        s.windows_per_s = double(settings.windows) / (1e-9 * double(now_ns() - measured_from));
        send("multibody", std::string());
        send("soil", std::string());
        for (auto &child : children)
            reap(child);
    } catch (...) {
        killAll(children);
        throw;
    }
    const rusage usage = minus(selfUsage(), before);
    s.coordinator_cpu_us = 1e6 * cpuSeconds(usage) / double(total);
    s.multibody_cpu_us = 1e6 * cpuSeconds(children[0].usage) / double(total);
    s.soil_cpu_us = 1e6 * cpuSeconds(children[1].usage) / double(total);
    s.switches_per_window =
        (switches(usage) + switches(children[0].usage) + switches(children[1].usage)) /
        double(total);
    return s;
}

// ------------------------------------------------------------------ report

/// Median over runs of a per-run figure.
template <typename F> double overRuns(const std::vector<Sample> &runs, F figure) {
    std::vector<double> values;
    for (const auto &r : runs)
        values.push_back(figure(r));
    return percentile(values, 0.5);
}

void printReport(const std::vector<Case> &cases, const std::vector<std::vector<Sample>> &samples,
                 const Settings &settings) {
    const auto median = [](const std::vector<double> &v) { return percentile(v, 0.5); };
    const auto p99 = [](const std::vector<double> &v) { return percentile(v, 0.99); };
    const std::size_t runs = samples.front().size();
    std::printf("\nCoupling window wall time, %d bodies, %llu windows after %llu warm-up, "
                "%zu run(s) per case, coupling.csv %s\n",
                kBodies, static_cast<unsigned long long>(settings.windows),
                static_cast<unsigned long long>(settings.warmup), runs,
                settings.csv ? "written" : "off");
    std::printf("(figures: median over runs of each run's statistic; spread: min..max of the "
                "runs' medians)\n\n");
    std::printf("%-9s %-8s %8s %10s %15s %9s %10s %10s\n", "transport", "scheme", "windows",
                "median", "spread", "p99", "windows/s", "median/");
    std::printf("%-9s %-8s %8s %10s %15s %9s %10s %10s\n", "", "", "", "[us]", "[us]", "[us]", "",
                "100 us");
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const auto &r = samples[i];
        const Case &c = cases[i];
        std::vector<double> medians;
        for (const auto &s : r)
            medians.push_back(median(s.wall_us));
        const double m = overRuns(r, [&](const Sample &s) { return median(s.wall_us); });
        char spread[32];
        std::snprintf(spread, sizeof spread, "%.1f..%.1f",
                      *std::min_element(medians.begin(), medians.end()),
                      *std::max_element(medians.begin(), medians.end()));
        std::printf("%-9s %-8s %8llu %10.1f %15s %9.1f %10.0f %10.2f\n",
                    (c.floor ? c.transport + "*" : c.transport).c_str(), schemeLabel(c).c_str(),
                    static_cast<unsigned long long>(settings.windows), m, spread,
                    overRuns(r, [&](const Sample &s) { return p99(s.wall_us); }),
                    overRuns(r, [](const Sample &s) { return s.windows_per_s; }),
                    m / kTargetMedian_us);
    }

    std::printf("\nWhere a window's time goes (medians over windows, then over runs) [us]\n\n");
    std::printf("%-9s %-8s %12s %10s %10s %10s %8s %8s %8s %9s %8s\n", "transport", "scheme",
                "participants", "coord.", "coord.", "csv", "CPU", "CPU", "CPU", "ctx sw",
                "one CPU");
    std::printf("%-9s %-8s %12s %10s %10s %10s %8s %8s %8s %9s %8s\n", "", "", "held", "overhead",
                "ovh. p99", "wall_s", "coord", "mb", "soil", "/window", "[%]");
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const auto &r = samples[i];
        const Case &c = cases[i];
        const auto figure = [&](auto f) { return overRuns(r, f); };
        const bool has_csv = !r.front().csv_wall_us.empty();
        char held[16] = "-", om[16] = "-", op[16] = "-", csv[16] = "-", same[16] = "-";
        if (!c.floor) {
            std::snprintf(same, sizeof same, "%.0f",
                          figure([](const Sample &s) { return s.same_cpu_percent; }));
            std::snprintf(held, sizeof held, "%.1f",
                          figure([&](const Sample &s) { return median(s.participants_us); }));
            std::snprintf(om, sizeof om, "%.1f",
                          figure([&](const Sample &s) { return median(s.overhead_us); }));
            std::snprintf(op, sizeof op, "%.1f",
                          figure([&](const Sample &s) { return p99(s.overhead_us); }));
        }
        if (has_csv)
            std::snprintf(csv, sizeof csv, "%.1f",
                          figure([&](const Sample &s) { return median(s.csv_wall_us); }));
        std::printf("%-9s %-8s %12s %10s %10s %10s %8.1f %8.1f %8.1f %9.1f %8s\n",
                    (c.floor ? c.transport + "*" : c.transport).c_str(), schemeLabel(c).c_str(),
                    held, om, op, csv, figure([](const Sample &s) { return s.coordinator_cpu_us; }),
                    figure([](const Sample &s) { return s.multibody_cpu_us; }),
                    figure([](const Sample &s) { return s.soil_cpu_us; }),
                    figure([](const Sample &s) { return s.switches_per_window; }), same);
    }
    std::printf(
        "\nwindow wall time: from the multibody participant's waitForCommand() returning one\n"
        "  window to it returning the next (CLOCK_MONOTONIC): one full coupling period.\n"
        "participants held: time from waitForCommand() returning to advance() returning, both\n"
        "  participants (union of the two intervals); no physics, so this is the participant\n"
        "  library's writeOutputs() checks, encode and send.\n"
        "coord. overhead: window wall time - participants held = the critical-path time in\n"
        "  which no participant holds the window: the coordinator's code plus the ZeroMQ hops\n"
        "  (decode in the participants included). With more busy threads than CPUs a\n"
        "  participant's interval also holds what the scheduler ran meanwhile; then read the\n"
        "  CPU columns and the difference to the * rows instead.\n"
        "csv wall_s: the coordinator's own per-window figure from coupling.csv (window start to\n"
        "  the end of its last WindowDone; it leaves out the CSV append and the next window's\n"
        "  set-up).\n"
        "CPU: user+system CPU per window of each process (all threads, ZeroMQ I/O included),\n"
        "  whole run / all windows; CPU coord = the coordinator's own cost per window.\n"
        "  ctx sw: voluntary+involuntary context switches, all three.\n"
        "one CPU: share of windows in which both participants opened the window on the same CPU\n"
        "  (the scheduler's placement; wake-ups across CPUs cost far more on a VM).\n");
    if (std::any_of(cases.begin(), cases.end(), [](const Case &c) { return c.floor; }))
        std::printf("ipc*/tcp*: bare ZeroMQ ROUTER/DEALER with the same messages per window and\n"
                    "  the same sizes, no protobuf, no checks: the transport's floor (wall time\n"
                    "  measured around the ROUTER's sends and receives).\n");
    std::printf("Target: median below %.0f us per window over ipc (ratio < 1).\n",
                kTargetMedian_us);
}

int runBenchmark(const std::vector<std::string> &transports,
                 const std::vector<std::string> &schemes, bool floor, unsigned runs,
                 Settings settings) {
    spdlog::set_level(spdlog::level::warn); // the coordinator's join lines would mix in the table
    std::vector<Case> cases;
    for (const auto &t : transports)
        for (const auto &s : schemes) {
            const auto kind = s == "serial" ? coupling::SchemeKind::ExplicitSerial
                                            : coupling::SchemeKind::ExplicitParallel;
            cases.push_back({t, kind, false});
            if (floor)
                cases.push_back({t, kind, true});
        }
    const bool own_work = settings.work.empty();
    if (own_work) {
        std::string pattern = (fs::temp_directory_path() / "coupling_bench.XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw std::runtime_error("cannot create a work directory under /tmp");
        settings.work = pattern;
    }
    std::vector<std::vector<Sample>> samples(cases.size());
    for (unsigned run = 0; run < runs; ++run) // runs interleaved, so load changes hit all cases
        for (std::size_t i = 0; i < cases.size(); ++i) {
            const Case &c = cases[i];
            const std::string directory = settings.work + "/" + c.transport + "_" + schemeLabel(c) +
                                          (c.floor ? "_floor" : "");
            fs::remove_all(directory);
            fs::create_directories(directory);
            samples[i].push_back(c.floor ? runFloor(c, settings, directory)
                                         : runCoupled(c, settings, directory));
            fs::remove_all(directory); // coupling.csv is ~2.5 kB a window
            const auto &s = samples[i].back();
            std::fprintf(stderr, "run %u: %s%s %-8s median %.1f us  p99 %.1f us\n", run + 1,
                         c.transport.c_str(), c.floor ? "*" : "", schemeLabel(c).c_str(),
                         percentile(s.wall_us, 0.5), percentile(s.wall_us, 0.99));
        }
    if (own_work)
        fs::remove_all(settings.work);
    printReport(cases, samples, settings);
    return 0;
}

} // namespace

int main(int argc, char **argv) {
    CLI::App app{"round-trip wall time of one coupling window (6 bodies, coordinator and two "
                 "participant processes); prints figures, asserts nothing"};
    Settings settings;
    std::string transport = "both", scheme = "both";
    unsigned runs = 3;
    bool floor = false, no_csv = false;
    app.add_option("--windows", settings.windows, "measured windows per run")
        ->check(CLI::PositiveNumber);
    app.add_option("--warmup", settings.warmup, "windows before measuring");
    app.add_option("--transport", transport, "ipc, tcp or both")
        ->check(CLI::IsMember({"ipc", "tcp", "both"}));
    app.add_option("--scheme", scheme, "serial, parallel or both")
        ->check(CLI::IsMember({"serial", "parallel", "both"}));
    app.add_option("--runs", runs, "runs per case (interleaved)")->check(CLI::PositiveNumber);
    app.add_flag("--no-csv", no_csv, "no output directory: the coordinator writes no coupling.csv");
    app.add_flag("--floor", floor, "also the bare-ZeroMQ floor of each case");
    app.add_option("--work", settings.work, "directory for sockets and files (default: /tmp)");

    std::string role, endpoint, extra;
    auto *participant = app.add_subcommand("participant", "(internal) a participant process");
    participant->add_option("role", role)->required()->check(CLI::IsMember({"multibody", "soil"}));
    participant->add_option("endpoint", endpoint)->required();
    participant->add_option("stamps", extra)->required();
    auto *floor_participant =
        app.add_subcommand("floor-participant", "(internal) a bare ZeroMQ echo process");
    floor_participant->add_option("name", role)->required();
    floor_participant->add_option("endpoint", endpoint)->required();
    floor_participant->add_option("reply_bytes", extra)->required();
    CLI11_PARSE(app, argc, argv);

    try {
        if (participant->parsed())
            return runParticipant(role, endpoint, extra);
        if (floor_participant->parsed())
            return runFloorParticipant(role, endpoint, std::stoul(extra));
        settings.csv = !no_csv;
        const auto both = [](const std::string &v, std::vector<std::string> all) {
            return v == "both" ? all : std::vector<std::string>{v};
        };
        return runBenchmark(both(transport, {"ipc", "tcp"}), both(scheme, {"serial", "parallel"}),
                            floor, runs, settings);
    } catch (const std::exception &e) {
        const std::string who = participant->parsed() ? " (" + role + ")" : "";
        std::fprintf(stderr, "coupling_bench%s: error: %s\n", who.c_str(), e.what());
        return 1;
    }
}
