#include "CouplingSeries.hpp"

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
    std::fprintf(file_, "%llu,%.17g,%.17g,%.17g,%u,%.6g,%.17g,%.17g,%.17g,%.17g,%.6g",
                 static_cast<unsigned long long>(row.window), row.start_s, row.end_s,
                 row.end_s - row.start_s, row.iterations, row.residual, row.work_multibody_J,
                 row.work_soil_J, row.work_multibody_J - row.work_soil_J, row.cumulative_mismatch_J,
                 row.wall_s);
    for (std::size_t b = 0; b < states.size(); ++b) {
        const auto &s = states[b];
        const auto &w = wrenches[b];
        const double values[] = {s.position_m.x(),
                                 s.position_m.y(),
                                 s.position_m.z(),
                                 s.orientation.w(),
                                 s.orientation.x(),
                                 s.orientation.y(),
                                 s.orientation.z(),
                                 s.linear_velocity_m_s.x(),
                                 s.linear_velocity_m_s.y(),
                                 s.linear_velocity_m_s.z(),
                                 s.angular_velocity_rad_s.x(),
                                 s.angular_velocity_rad_s.y(),
                                 s.angular_velocity_rad_s.z(),
                                 w.force_N.x(),
                                 w.force_N.y(),
                                 w.force_N.z(),
                                 w.torque_N_m.x(),
                                 w.torque_N_m.y(),
                                 w.torque_N_m.z()};
        for (double v : values)
            std::fprintf(file_, ",%.17g", v);
    }
    std::fputc('\n', file_);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_flush_ > std::chrono::milliseconds(500))
        flush();
}

void CouplingSeries::flush() {
    std::fflush(file_);
    last_flush_ = std::chrono::steady_clock::now();
}

} // namespace grainlink::coupling
