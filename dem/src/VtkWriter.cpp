#include "grainlink/dem/VtkWriter.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace grainlink::dem {

namespace {

std::string numbered(const std::string &prefix, int index) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%06d.vtu", prefix.c_str(), index);
    return name;
}

void openOrThrow(std::ofstream &out, const std::string &path) {
    out.open(path);
    if (!out)
        throw std::runtime_error("cannot write snapshot '" + path + "'");
    out.precision(9);
}

/// Completes a snapshot written to `path`.partial: renamed over `path` in one step, so a crash
/// while writing leaves the previous file (or none), never a cut one.
void commit(std::ofstream &out, const std::string &path) {
    out.close();
    if (!out)
        throw std::runtime_error("cannot write snapshot '" + path + "': " + std::strerror(errno));
    if (std::rename((path + ".partial").c_str(), path.c_str()) != 0)
        throw std::runtime_error("cannot rename '" + path + ".partial' to '" + path + "'");
}

template <class Get>
void vectorArray(std::ofstream &out, const char *name, std::size_t n, Get get) {
    out << "<DataArray type=\"Float64\" Name=\"" << name
        << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 v = get(i);
        out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    }
    out << "</DataArray>\n";
}

void writeMesh(const MeshBody &body, const std::string &path) {
    std::ofstream out;
    openOrThrow(out, path + ".partial");
    const auto &v = body.worldVertices();
    const auto &t = body.mesh().triangles;
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
        << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << v.size() << "\" NumberOfCells=\""
        << t.size() << "\">\n<Points>\n";
    vectorArray(out, "position_m", v.size(), [&](std::size_t i) { return v[i]; });
    out << "</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (const auto &tri : t)
        out << tri[0] << ' ' << tri[1] << ' ' << tri[2] << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t k = 0; k < t.size(); ++k)
        out << 3 * (k + 1) << '\n';
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t k = 0; k < t.size(); ++k)
        out << "5\n"; // VTK_TRIANGLE
    out << "</DataArray>\n</Cells>\n";
    if (body.record_triangle_loads) {
        out << "<CellData>\n";
        vectorArray(out, "force_N", t.size(),
                    [&](std::size_t k) { return body.triangle_force_N[k]; });
        out << "</CellData>\n";
    }
    out << "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    commit(out, path);
}

} // namespace

VtkWriter::VtkWriter(std::string directory) : directory_(std::move(directory)) {}

void VtkWriter::writeParticles(const ParticleStore &p, const std::string &path) {
    std::ofstream out;
    openOrThrow(out, path + ".partial");
    const std::size_t n = p.size();
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
        << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n
        << "\">\n"
        << "<Points>\n";
    vectorArray(out, "position_m", n, [&](std::size_t i) { return p.position[i]; });
    out << "</Points>\n<PointData Scalars=\"radius_m\" Vectors=\"velocity_m_s\">\n"
        << "<DataArray type=\"Int64\" Name=\"id\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i)
        out << p.id[i] << '\n';
    out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"radius_m\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i)
        out << p.radius[i] << '\n';
    out << "</DataArray>\n";
    vectorArray(out, "velocity_m_s", n, [&](std::size_t i) { return p.velocity[i]; });
    vectorArray(out, "angular_velocity_rad_s", n,
                [&](std::size_t i) { return p.angular_velocity[i]; });
    vectorArray(out, "force_N", n, [&](std::size_t i) { return p.force[i]; });
    // One vertex cell per grain: without cells ParaView's default (Surface) view shows nothing.
    out << "</PointData>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i)
        out << i << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i)
        out << i + 1 << '\n';
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i)
        out << "1\n"; // VTK_VERTEX
    out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    commit(out, path);
}

void VtkWriter::write(const DemSystem &system, double time_s) {
    const int index = int(times_.size());
    writeParticles(system.particles(), directory_ + "/" + numbered("particles", index));
    body_names_.clear();
    for (int b = 0; b < system.bodyCount(); ++b) {
        const std::string prefix = "body_" + system.body(b).name();
        writeMesh(system.body(b), directory_ + "/" + numbered(prefix, index));
        body_names_.push_back(system.body(b).name());
    }
    times_.push_back(time_s);
    writeCollection("particles.pvd", "particles");
    for (const std::string &name : body_names_)
        writeCollection("body_" + name + ".pvd", "body_" + name);
}

void VtkWriter::resumeAt(int index, const std::vector<double> &times_s) {
    times_.assign(times_s.begin(),
                  times_s.begin() + std::min<std::size_t>(std::size_t(index), times_s.size()));
}

void VtkWriter::writeCollection(const std::string &name, const std::string &prefix) const {
    const std::string path = directory_ + "/" + name;
    std::ofstream out(path + ".partial");
    if (!out)
        throw std::runtime_error("cannot write '" + path + "'");
    out.precision(12);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
    for (std::size_t k = 0; k < times_.size(); ++k)
        out << "<DataSet timestep=\"" << times_[k] << "\" file=\"" << numbered(prefix, int(k))
            << "\"/>\n";
    out << "</Collection>\n</VTKFile>\n";
    commit(out, path);
}

} // namespace grainlink::dem
