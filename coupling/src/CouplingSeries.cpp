#include "CouplingSeries.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace grainlink::coupling {

namespace fs = std::filesystem;

namespace {

std::string header(const std::vector<std::string> &bodies) {
    std::string h = "window,start_s,end_s,macro_step_s,iterations,residual,work_multibody_J,"
                    "work_soil_J,energy_mismatch_J,cumulative_mismatch_J,wall_s";
    for (const auto &b : bodies)
        for (const char *column :
             {"x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s",
              "wy_rad_s", "wz_rad_s", "Fx_N", "Fy_N", "Fz_N", "Tx_N_m", "Ty_N_m", "Tz_N_m"})
            h += "," + b + "." + column;
    return h;
}

} // namespace

CouplingSeries::CouplingSeries(const std::string &directory, const std::vector<std::string> &bodies,
                               std::optional<std::uint64_t> resume_window)
    : path_((fs::path(directory) / "coupling.csv").string()) {
    fs::create_directories(directory);
    const std::string expected_header = header(bodies);
    std::vector<std::string> kept;
    if (resume_window) {
        std::ifstream in(path_);
        std::string line;
        if (std::getline(in, line) && line != expected_header)
            throw CouplingError(path_ +
                                ": the columns differ from this run's bodies; cannot resume");
        for (int number = 2; std::getline(in, line); ++number) {
            // A row begins with its window; a damaged one is named, not read as a number.
            const std::string first = line.substr(0, line.find(','));
            if (first.empty() || first.size() > 18 ||
                first.find_first_not_of("0123456789") != std::string::npos)
                throw CouplingError(path_ + ": line " + std::to_string(number) +
                                    " does not begin with a window number ('" + line.substr(0, 40) +
                                    "'); cannot resume");
            if (std::stoull(first) < *resume_window)
                kept.push_back(line);
        }
    }
    // The kept rows go to a file beside it, synced and renamed over it: a crash while resuming
    // never loses them. Then rows are appended.
    const std::string partial = path_ + ".partial";
    std::FILE *fresh = std::fopen(partial.c_str(), "w");
    if (!fresh)
        throw CouplingError("cannot write " + partial + ": " + std::strerror(errno));
    std::fprintf(fresh, "%s\n", expected_header.c_str());
    for (const auto &line : kept)
        std::fprintf(fresh, "%s\n", line.c_str());
    const bool written = std::fflush(fresh) == 0 && ::fsync(::fileno(fresh)) == 0;
    const int error = errno;
    std::fclose(fresh);
    if (!written || std::rename(partial.c_str(), path_.c_str()) != 0)
        throw CouplingError("cannot write " + path_ + ": " +
                            std::strerror(written ? errno : error));
    file_ = std::fopen(path_.c_str(), "a");
    if (!file_)
        throw CouplingError("cannot write " + path_ + ": " + std::strerror(errno));
    writer_ = std::thread([this] { writerLoop(); });
}

CouplingSeries::~CouplingSeries() {
    {
        std::lock_guard lock(queue_mutex_);
        stop_ = true;
    }
    wake_.notify_one();
    writer_.join();
    writeQueued();
    std::fclose(file_);
}

void CouplingSeries::append(const Row &row, const std::vector<BodyState> &states,
                            const std::vector<Wrench> &wrenches) {
    // Copies into reused storage under an uncontended lock, and no wake-up call: the writer
    // looks by itself every 0.1 s.
    std::lock_guard lock(queue_mutex_);
    if (spare_.empty())
        queued_.emplace_back();
    else {
        queued_.push_back(std::move(spare_.back()));
        spare_.pop_back();
    }
    Entry &e = queued_.back();
    e.row = row;
    e.states.assign(states.begin(), states.end());
    e.wrenches.assign(wrenches.begin(), wrenches.end());
}

void CouplingSeries::check() const {
    std::lock_guard write_lock(write_mutex_);
    if (!error_.empty())
        throw CouplingError(error_);
}

void CouplingSeries::flush() {
    writeQueued();
    check();
}

void CouplingSeries::writerLoop() {
    std::unique_lock lock(queue_mutex_);
    while (!stop_) {
        wake_.wait_for(lock, std::chrono::milliseconds(100));
        lock.unlock();
        writeQueued();
        lock.lock();
    }
}

void CouplingSeries::writeQueued() {
    std::lock_guard write_lock(write_mutex_);
    {
        std::lock_guard lock(queue_mutex_);
        writing_.swap(queued_);
    }
    if (writing_.empty())
        return;
    for (const Entry &e : writing_) {
        const Row &row = e.row;
        const auto &states = e.states;
        const auto &wrenches = e.wrenches;
        // Shortest round-trip text (std::to_chars) into one reused buffer, one fwrite per row.
        line_.clear();
        auto put = [this](auto value) {
            char text[32];
            const auto end = std::to_chars(text, text + sizeof text, value).ptr;
            line_.append(text, end);
            line_.push_back(',');
        };
        put(row.window);
        put(row.start_s);
        put(row.end_s);
        put(row.end_s - row.start_s);
        put(row.iterations);
        put(row.residual);
        put(row.work_multibody_J);
        put(row.work_soil_J);
        put(row.work_multibody_J - row.work_soil_J);
        put(row.cumulative_mismatch_J);
        put(row.wall_s);
        for (std::size_t b = 0; b < states.size(); ++b) {
            const auto &s = states[b];
            const auto &w = wrenches[b];
            for (const Vec3 *v : {&s.position_m})
                for (int k = 0; k < 3; ++k)
                    put((*v)[k]);
            put(s.orientation.w());
            put(s.orientation.x());
            put(s.orientation.y());
            put(s.orientation.z());
            for (const Vec3 *v :
                 {&s.linear_velocity_m_s, &s.angular_velocity_rad_s, &w.force_N, &w.torque_N_m})
                for (int k = 0; k < 3; ++k)
                    put((*v)[k]);
        }
        line_.back() = '\n';
        if (std::fwrite(line_.data(), 1, line_.size(), file_) != line_.size() && error_.empty())
            error_ = "cannot write " + path_ + ": " + std::strerror(errno);
    }
    if (std::fflush(file_) != 0 && error_.empty())
        error_ = "cannot write " + path_ + ": " + std::strerror(errno);
    std::lock_guard lock(queue_mutex_);
    for (auto &e : writing_)
        spare_.push_back(std::move(e));
    writing_.clear();
}

} // namespace grainlink::coupling
