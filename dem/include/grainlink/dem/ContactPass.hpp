#pragma once
// What the contact passes (PairContacts, PlaneContacts, MeshContacts) share: a thread's worst
// overlap, per-thread sums kept off each other's cache lines, and the batch size of their loops.
#include "grainlink/dem/Types.hpp"

#include <cstddef>
#include <vector>

namespace grainlink::dem {

/// Contacts are tested and evaluated in batches of this many candidates: first which touch
/// (without a branch on the answer), then the contacts, so that consecutive contacts overlap
/// in the processor instead of each waiting on a mispredicted branch.
constexpr std::size_t kContactBatch = 128;

/// Largest overlap relative to the smaller radius that one thread met in a step, and where.
struct WorstOverlap {
    double ratio = 0.0;
    ParticleId i = 0, j = 0;   ///< the pair; j == i against a wall
    int plane = -1, body = -1; ///< against a wall: the plane's or the mesh body's index
    void offer(double overlap_m, double radius_m, ParticleId a, ParticleId b, int plane_k = -1,
               int body_k = -1) {
        if (overlap_m > ratio * radius_m) { // no division for the (common) smaller overlap
            ratio = overlap_m / radius_m;
            i = a;
            j = b;
            plane = plane_k;
            body = body_k;
        }
    }
};

/// n zero sums for one thread. Each thread adds into its own wall and body sums at every wall
/// or mesh contact; separate small allocations may lie side by side in memory, so a cache line
/// of slack after each keeps two threads off one line (false sharing would bounce it between
/// cores on every contact).
inline std::vector<Vec3> perThreadSums(std::size_t n) {
    constexpr std::size_t kSlack = (64 + sizeof(Vec3) - 1) / sizeof(Vec3);
    std::vector<Vec3> sums;
    sums.reserve(n + kSlack);
    sums.resize(n, Vec3::Zero());
    return sums;
}

} // namespace grainlink::dem
