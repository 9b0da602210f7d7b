#include "grainlink/dem/ParticleStore.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace grainlink::dem {

namespace {
template <class T> void applyOrder(std::vector<T> &values, const std::vector<std::size_t> &order) {
    std::vector<T> sorted;
    sorted.reserve(values.size());
    for (std::size_t k : order)
        sorted.push_back(values[k]);
    values.swap(sorted);
}
} // namespace

ParticleId ParticleStore::add(const ParticleSpec &spec) {
    if (!(spec.radius_m > 0.0) || !std::isfinite(spec.radius_m)) {
        std::ostringstream msg;
        msg << "particle radius must be positive and finite, got " << spec.radius_m << " m";
        throw std::invalid_argument(msg.str());
    }
    if (!(spec.density_kg_m3 > 0.0) || !std::isfinite(spec.density_kg_m3)) {
        std::ostringstream msg;
        msg << "particle density must be positive and finite, got " << spec.density_kg_m3
            << " kg/m^3";
        throw std::invalid_argument(msg.str());
    }
    const double r = spec.radius_m;
    const double m = 4.0 / 3.0 * M_PI * r * r * r * spec.density_kg_m3;
    Vec3 inertia_kg_m2 = spec.inertia_kg_m2;
    if (inertia_kg_m2.isZero())
        inertia_kg_m2.setConstant(0.4 * m * r * r); // solid sphere
    if ((inertia_kg_m2.array() <= 0.0).any())
        throw std::invalid_argument("particle moments of inertia must all be positive");

    const ParticleId new_id = next_id_++;
    id.push_back(new_id);
    position.push_back(spec.position_m);
    velocity.push_back(spec.velocity_m_s);
    angular_velocity.push_back(spec.angular_velocity_rad_s);
    orientation.push_back(Quat::Identity());
    force.push_back(Vec3::Zero());
    torque.push_back(Vec3::Zero());
    radius.push_back(r);
    mass.push_back(m);
    inv_mass.push_back(1.0 / m);
    inertia.push_back(inertia_kg_m2);
    material.push_back(spec.material);
    return new_id;
}

void ParticleStore::reserve(std::size_t n) {
    id.reserve(n);
    position.reserve(n);
    velocity.reserve(n);
    angular_velocity.reserve(n);
    orientation.reserve(n);
    force.reserve(n);
    torque.reserve(n);
    radius.reserve(n);
    mass.reserve(n);
    inv_mass.reserve(n);
    inertia.reserve(n);
    material.reserve(n);
}

void ParticleStore::permute(const std::vector<std::size_t> &order) {
    if (order.size() != size())
        throw std::logic_error("ParticleStore::permute: wrong order size");
    select(order);
}

void ParticleStore::keep(const std::vector<std::size_t> &kept) {
    for (std::size_t k = 0; k < kept.size(); ++k)
        if (kept[k] >= size() || (k > 0 && kept[k] <= kept[k - 1]))
            throw std::logic_error("ParticleStore::keep: indices must ascend within the store");
    select(kept);
}

void ParticleStore::select(const std::vector<std::size_t> &order) {
    applyOrder(id, order);
    applyOrder(position, order);
    applyOrder(velocity, order);
    applyOrder(angular_velocity, order);
    applyOrder(orientation, order);
    applyOrder(force, order);
    applyOrder(torque, order);
    applyOrder(radius, order);
    applyOrder(mass, order);
    applyOrder(inv_mass, order);
    applyOrder(inertia, order);
    applyOrder(material, order);
}

double ParticleStore::maxRadius() const {
    return radius.empty() ? 0.0 : *std::max_element(radius.begin(), radius.end());
}
double ParticleStore::minRadius() const {
    return radius.empty() ? 0.0 : *std::min_element(radius.begin(), radius.end());
}

} // namespace grainlink::dem
