#pragma once
// Particle and mesh snapshots as VTK XML unstructured grids, collected in a ParaView .pvd file.
// Every file is written to `<name>.partial` and renamed over `<name>` when complete: a crash
// while writing never leaves a cut snapshot or collection.
#include "grainlink/dem/DemSystem.hpp"

#include <string>
#include <vector>

namespace grainlink::dem {

class VtkWriter {
public:
    /// Snapshots go to `directory`/particles_NNNNNN.vtu (and body_<name>_NNNNNN.vtu; with
    /// `contact_network`, the force chains as contacts_NNNNNN.vtu: a line between the centres
    /// of each touching pair, its cell data the elastic normal force `normal_force_N`).
    explicit VtkWriter(std::string directory, bool contact_network = false);
    /// Writes one snapshot; the .pvd collections are rewritten so they are valid after each call.
    void write(const DemSystem &system, double time_s);
    /// Writes particles only, to an explicit path (failure snapshots).
    static void writeParticles(const ParticleStore &particles, const std::string &path);
    /// Restarts numbering after a resume so earlier snapshots stay in the collection.
    void resumeAt(int index, const std::vector<double> &times_s);
    int count() const { return int(times_.size()); }
    const std::vector<double> &times() const { return times_; }

private:
    void writeCollection(const std::string &name, const std::string &prefix) const;
    std::string directory_;
    bool contact_network_ = false;
    std::vector<double> times_;
    std::vector<std::string> body_names_;
};

} // namespace grainlink::dem
