#include "CheckpointFiles.hpp"

#include "Codec.hpp"
#include "grainlink/config/Checksum.hpp"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace grainlink::coupling {

namespace fs = std::filesystem;

namespace {

/// Written aside, synced to the disk, and renamed over `path`: whole or absent after a crash.
void writeAtomically(const fs::path &path, const std::string &bytes) {
    const std::string temporary = path.string() + ".tmp";
    std::FILE *out = std::fopen(temporary.c_str(), "wb");
    const bool written = out && std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size() &&
                         std::fflush(out) == 0 && ::fsync(::fileno(out)) == 0;
    if (out)
        std::fclose(out);
    if (!written)
        throw CouplingError("cannot write " + temporary);
    fs::rename(temporary, path);
}

fs::path latestFile(const std::string &output_directory) {
    return fs::path(output_directory) / "checkpoints" / "latest";
}

constexpr const char *kManifest = "manifest.txt";
constexpr std::size_t kCheckpointsKept = 3; ///< the latest and the two before it

/// A file's checksum and size; false when it cannot be read.
bool checksumOf(const fs::path &path, std::uint64_t &sum, std::uintmax_t &size) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return false;
    config::Checksum c;
    char buffer[1 << 16];
    size = 0;
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
        c.add(buffer, std::size_t(in.gcount()));
        size += std::uintmax_t(in.gcount());
    }
    sum = c.value;
    return !in.bad();
}

/// The manifest's last line: how many files it lists and the checksum of the lines above, so
/// that a manifest cut short (or emptied) is itself found damaged.
std::string manifestEnd(const std::string &lines, std::size_t files) {
    config::Checksum c;
    c.add(lines.data(), lines.size());
    char end[64];
    std::snprintf(end, sizeof end, "end %zu %016llx\n", files,
                  static_cast<unsigned long long>(c.value));
    return end;
}

std::string manifestLine(std::uint64_t sum, std::uintmax_t size, const std::string &name) {
    char line[48];
    std::snprintf(line, sizeof line, "%016llx %llu ", static_cast<unsigned long long>(sum),
                  static_cast<unsigned long long>(size));
    return line + name + '\n';
}

/// Every participant's file in a checkpoint and the coordinator.pb about to be written, each
/// with its checksum and size (manifest.txt), so that a damaged one is found before any
/// participant believes it. Written before coordinator.pb: a crash between the two leaves a
/// checkpoint without its coordinator.pb, which is refused.
void writeManifest(const fs::path &directory, const std::string &coordinator_pb) {
    std::vector<fs::path> files;
    for (const auto &entry : fs::recursive_directory_iterator(directory))
        if (entry.is_regular_file() && entry.path().filename() != kManifest &&
            entry.path().filename() != "coordinator.pb")
            files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    std::string text;
    for (const fs::path &file : files) {
        std::uint64_t sum = 0;
        std::uintmax_t size = 0;
        if (!checksumOf(file, sum, size))
            throw CouplingError("cannot read " + file.string() + " to checksum it");
        text += manifestLine(sum, size, fs::relative(file, directory).string());
    }
    config::Checksum c;
    c.add(coordinator_pb.data(), coordinator_pb.size());
    text += manifestLine(c.value, coordinator_pb.size(), "coordinator.pb");
    writeAtomically(directory / kManifest, text + manifestEnd(text, files.size() + 1));
}

/// What is wrong with a checkpoint folder; empty when it is whole. One written before the
/// manifest existed is checked by its coordinator.pb alone.
std::string damage(const fs::path &folder, codec::pb::CoordinatorCheckpoint &state) {
    std::ifstream state_file(folder / "coordinator.pb", std::ios::binary);
    if (!state_file || !state.ParseFromIstream(&state_file))
        return "coordinator.pb is missing or unreadable";
    std::ifstream manifest(folder / kManifest);
    if (!manifest)
        return fs::exists(folder / kManifest) ? "manifest.txt is unreadable" : "";
    std::vector<std::string> lines;
    for (std::string line; std::getline(manifest, line);)
        lines.push_back(line);
    std::string listed;
    for (std::size_t k = 0; k + 1 < lines.size(); ++k)
        listed += lines[k] + '\n';
    if (lines.empty() || lines.back() + '\n' != manifestEnd(listed, lines.size() - 1))
        return "manifest.txt is cut short or changed (its end line does not match)";
    lines.pop_back();
    for (const std::string &line : lines) {
        std::istringstream cells(line);
        std::string hex, name;
        std::uintmax_t size = 0;
        if (!(cells >> hex >> size) || !std::getline(cells >> std::ws, name))
            return "manifest.txt has a damaged line '" + line + "'";
        std::uint64_t sum = 0;
        std::uintmax_t actual = 0;
        if (!checksumOf(folder / name, sum, actual))
            return name + " is missing or unreadable";
        if (actual != size)
            return name + " has " + std::to_string(actual) + " bytes, " + std::to_string(size) +
                   " when it was written";
        if (std::strtoull(hex.c_str(), nullptr, 16) != sum)
            return name + " does not match its checksum (it changed after it was written)";
    }
    return "";
}

} // namespace

std::string checkpointDirectory(const std::string &output_directory, std::uint64_t window) {
    char name[32];
    std::snprintf(name, sizeof name, "window_%09llu", static_cast<unsigned long long>(window));
    return fs::absolute(fs::path(output_directory) / "checkpoints" / name).string();
}

void commitCheckpoint(const std::string &output_directory, const std::string &directory,
                      const CoordinatorSnapshot &snapshot) {
    codec::pb::CoordinatorCheckpoint state;
    state.set_run_id(snapshot.run_id);
    state.set_window(snapshot.window);
    state.set_tick(snapshot.tick);
    state.set_macro_step_ticks(snapshot.macro_step_ticks);
    codec::toWire(snapshot.states, snapshot.tick, state.mutable_states());
    codec::toWire(snapshot.wrenches, snapshot.tick, snapshot.tick, state.mutable_wrenches());
    state.set_cumulative_mismatch_j(snapshot.cumulative_mismatch_J);
    const std::string bytes = state.SerializeAsString();
    writeManifest(directory, bytes);
    writeAtomically(fs::path(directory) / "coordinator.pb", bytes);
    const std::string name = fs::path(directory).filename().string();
    writeAtomically(latestFile(output_directory), name + "\n");
    // Two earlier checkpoints stay for a resume to fall back on; older ones go, so that a long
    // run does not fill the disk (the demo's are 27 MB each).
    std::vector<std::string> earlier;
    for (const auto &entry : fs::directory_iterator(fs::path(directory).parent_path()))
        if (entry.is_directory() && entry.path().filename().string().rfind("window_", 0) == 0 &&
            entry.path().filename().string() < name)
            earlier.push_back(entry.path().filename().string());
    std::sort(earlier.begin(), earlier.end());
    for (std::size_t k = 0; k + kCheckpointsKept - 1 < earlier.size(); ++k)
        fs::remove_all(fs::path(directory).parent_path() / earlier[k]);
}

CoordinatorSnapshot readLatestCheckpoint(const std::string &output_directory,
                                         std::string &directory) {
    const fs::path latest = latestFile(output_directory);
    std::ifstream in(latest);
    std::string name;
    if (!(in >> name))
        throw CouplingError("cannot resume: no complete checkpoint (" + latest.string() +
                            " is missing)");
    // The latest first, then the ones before it, newest first: a damaged checkpoint is passed
    // over, never believed.
    std::vector<std::string> names;
    for (const auto &entry : fs::directory_iterator(latest.parent_path()))
        if (entry.is_directory() && entry.path().filename().string().rfind("window_", 0) == 0 &&
            entry.path().filename().string() < name)
            names.push_back(entry.path().filename().string());
    std::sort(names.rbegin(), names.rend());
    names.insert(names.begin(), name);
    codec::pb::CoordinatorCheckpoint state;
    std::string problems;
    for (const std::string &candidate : names) {
        const fs::path folder = fs::absolute(latest.parent_path() / candidate);
        const std::string problem = damage(folder, state);
        if (problem.empty()) {
            directory = folder.string();
            break;
        }
        spdlog::warn("coordinator: checkpoint {} is damaged: {}; trying the one before it",
                     folder.string(), problem);
        problems += "; " + candidate + ": " + problem;
    }
    if (directory.empty())
        throw CouplingError("cannot resume: every checkpoint in " + latest.parent_path().string() +
                            " is damaged" + problems);
    CoordinatorSnapshot snapshot;
    snapshot.run_id = state.run_id();
    snapshot.window = state.window();
    snapshot.tick = state.tick();
    snapshot.macro_step_ticks = state.macro_step_ticks();
    snapshot.states = codec::fromWire(state.states());
    snapshot.wrenches = codec::fromWire(state.wrenches());
    snapshot.cumulative_mismatch_J = state.cumulative_mismatch_j();
    return snapshot;
}

} // namespace grainlink::coupling
