#include "CheckpointFiles.hpp"

#include "Codec.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace grainlink::coupling {

namespace fs = std::filesystem;

namespace {

void writeAtomically(const fs::path &path, const std::string &bytes) {
    const std::string temporary = path.string() + ".tmp";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        if (!out.flush())
            throw CouplingError("cannot write " + temporary);
    }
    fs::rename(temporary, path);
}

fs::path latestFile(const std::string &output_directory) {
    return fs::path(output_directory) / "checkpoints" / "latest";
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
    writeAtomically(fs::path(directory) / "coordinator.pb", state.SerializeAsString());
    writeAtomically(latestFile(output_directory), fs::path(directory).filename().string() + "\n");
}

CoordinatorSnapshot readLatestCheckpoint(const std::string &output_directory,
                                         std::string &directory) {
    const fs::path latest = latestFile(output_directory);
    std::ifstream in(latest);
    std::string name;
    if (!(in >> name))
        throw CouplingError("cannot resume: no complete checkpoint (" + latest.string() +
                            " is missing)");
    const fs::path folder = fs::absolute(latest.parent_path() / name);
    std::ifstream state_file(folder / "coordinator.pb", std::ios::binary);
    codec::pb::CoordinatorCheckpoint state;
    if (!state.ParseFromIstream(&state_file))
        throw CouplingError("cannot resume: " + (folder / "coordinator.pb").string() +
                            " is unreadable");
    CoordinatorSnapshot snapshot;
    snapshot.run_id = state.run_id();
    snapshot.window = state.window();
    snapshot.tick = state.tick();
    snapshot.macro_step_ticks = state.macro_step_ticks();
    snapshot.states = codec::fromWire(state.states());
    snapshot.wrenches = codec::fromWire(state.wrenches());
    snapshot.cumulative_mismatch_J = state.cumulative_mismatch_j();
    directory = folder.string();
    return snapshot;
}

} // namespace grainlink::coupling
