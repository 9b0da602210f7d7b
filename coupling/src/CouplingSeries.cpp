#include "CouplingSeries.hpp"

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
              "wy_rad_s", "wz_rad_s", "fx_N", "fy_N", "fz_N", "tx_N_m", "ty_N_m", "tz_N_m"})
            h += "," + b + "." + column;
    return h;
}

} // namespace

CouplingSeries::CouplingSeries(const std::string &directory, const std::vector<std::string> &bodies,
                               std::optional<std::uint64_t> resume_window)
    : path_((fs::path(directory) / "coupling.csv").string()),
      last_flush_(std::chrono::steady_clock::now()) {
    fs::create_directories(directory);
    const std::string expected_header = header(bodies);
    std::vector<std::string> kept;
    if (resume_window) {
        std::ifstream in(path_);
        std::string line;
        if (std::getline(in, line) && line != expected_header)
            throw CouplingError(path_ +
                                ": the columns differ from this run's bodies; cannot resume");
        while (std::getline(in, line)) {
            const auto window = std::stoull(line.substr(0, line.find(',')));
            if (window < *resume_window)
                kept.push_back(line);
        }
    }
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
        throw CouplingError("cannot write " + path_);
    std::fprintf(file_, "%s\n", expected_header.c_str());
    for (const auto &line : kept)
        std::fprintf(file_, "%s\n", line.c_str());
    std::fflush(file_);
}

CouplingSeries::~CouplingSeries() {
    if (file_)
        std::fclose(file_);
}

void CouplingSeries::append(const Row &row, const std::vector<BodyState> &states,
                            const std::vector<Wrench> &wrenches) {
    // Shortest round-trip text (std::to_chars) into one reused buffer, one fwrite: the row is
    // written every window, so it must cost microseconds, not tens of them.
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
    std::fwrite(line_.data(), 1, line_.size(), file_);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_flush_ > std::chrono::milliseconds(500))
        flush();
}

void CouplingSeries::flush() {
    std::fflush(file_);
    last_flush_ = std::chrono::steady_clock::now();
}

} // namespace grainlink::coupling
