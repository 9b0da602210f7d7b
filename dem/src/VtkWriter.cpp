#include "grainlink/dem/VtkWriter.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <zlib.h>

namespace grainlink::dem {

namespace {

std::string numbered(const std::string &prefix, int index) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%06d.vtu", prefix.c_str(), index);
    return name;
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

/// One array's bytes as VTK's zlib compressor writes them (vtkZLibDataCompressor, header_type
/// UInt64): the block count, the block size, the last block's size (0 when it is full) and each
/// block's compressed size, then the compressed blocks. Lossless: every number keeps its bits.
std::string zlibBlocks(const std::vector<char> &bytes) {
    constexpr std::size_t kBlock = 1 << 16;
    const std::size_t blocks = (bytes.size() + kBlock - 1) / kBlock;
    std::vector<std::uint64_t> header{blocks, kBlock, bytes.size() % kBlock};
    std::string data;
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t n = std::min(kBlock, bytes.size() - b * kBlock);
        uLongf size = compressBound(uLong(n));
        std::string block(size, '\0');
        if (compress2(reinterpret_cast<Bytef *>(block.data()), &size,
                      reinterpret_cast<const Bytef *>(bytes.data() + b * kBlock), uLong(n),
                      Z_DEFAULT_COMPRESSION) != Z_OK)
            throw std::runtime_error("zlib could not compress a snapshot array");
        header.push_back(size);
        data.append(block.data(), size);
    }
    return std::string(reinterpret_cast<const char *>(header.data()),
                       header.size() * sizeof(std::uint64_t)) +
           data;
}

/// One .vtu file: its arrays are collected, then written as VTK XML, binary, little-endian,
/// appended and zlib-compressed as ParaView's own files are (a 62,000-grain snapshot raw took
/// about a third of the ASCII size; radii, ids and cell arrays compress far further).
class VtuFile {
public:
    enum class Section { Points, PointData, CellData, Cells };

    template <class T>
    void add(Section section, const char *type, const char *name, int components,
             const std::vector<T> &values) {
        static_assert(std::is_trivially_copyable_v<T>);
        Array a{section, type, name, components, {}};
        a.bytes.resize(values.size() * sizeof(T));
        if (!values.empty())
            std::memcpy(a.bytes.data(), values.data(), a.bytes.size());
        arrays_.push_back(std::move(a));
    }
    void vectors(Section section, const char *name, const std::vector<Vec3> &values) {
        std::vector<double> flat;
        flat.reserve(3 * values.size());
        for (const Vec3 &v : values)
            flat.insert(flat.end(), {v.x(), v.y(), v.z()});
        add(section, "Float64", name, 3, flat);
    }

    void write(const std::string &path, std::size_t points, std::size_t cells,
               const std::string &point_scalars = "") const {
        std::ofstream out(path + ".partial", std::ios::binary);
        if (!out)
            throw std::runtime_error("cannot write snapshot '" + path + "'");
        std::vector<std::string> blocks; // each array compressed, in the order written below
        for (const Section which :
             {Section::Points, Section::PointData, Section::CellData, Section::Cells})
            for (const Array &a : arrays_)
                if (a.section == which)
                    blocks.push_back(zlibBlocks(a.bytes));
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
               "byte_order=\"LittleEndian\" header_type=\"UInt64\" "
               "compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n"
            << "<Piece NumberOfPoints=\"" << points << "\" NumberOfCells=\"" << cells << "\">\n";
        std::uint64_t offset = 0;
        std::size_t next = 0; // the next array's compressed block
        const auto section = [&](Section which, const std::string &open, const std::string &close) {
            bool any = false;
            for (const Array &a : arrays_)
                any = any || a.section == which;
            if (!any && which != Section::Points && which != Section::Cells)
                return;
            out << open;
            for (const Array &a : arrays_)
                if (a.section == which) {
                    out << "<DataArray type=\"" << a.type << "\" Name=\"" << a.name
                        << "\" NumberOfComponents=\"" << a.components
                        << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
                    offset += blocks[next++].size();
                }
            out << close;
        };
        section(Section::Points, "<Points>\n", "</Points>\n");
        section(Section::PointData,
                point_scalars.empty() ? "<PointData>\n"
                                      : "<PointData Scalars=\"" + point_scalars + "\">\n",
                "</PointData>\n");
        section(Section::CellData, "<CellData>\n", "</CellData>\n");
        section(Section::Cells, "<Cells>\n", "</Cells>\n");
        out << "</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";
        for (const std::string &b : blocks)
            out.write(b.data(), std::streamsize(b.size()));
        out << "\n</AppendedData>\n</VTKFile>\n";
        commit(out, path);
    }

private:
    struct Array {
        Section section;
        const char *type;
        const char *name;
        int components;
        std::vector<char> bytes;
    };
    std::vector<Array> arrays_;
};

void writeMesh(const MeshBody &body, const std::string &path) {
    const auto &t = body.mesh().triangles;
    VtuFile file;
    file.vectors(VtuFile::Section::Points, "position_m", body.worldVertices());
    std::vector<std::int64_t> connectivity, offsets;
    for (const auto &tri : t) {
        connectivity.insert(connectivity.end(), {tri[0], tri[1], tri[2]});
        offsets.push_back(std::int64_t(connectivity.size()));
    }
    file.add(VtuFile::Section::Cells, "Int64", "connectivity", 1, connectivity);
    file.add(VtuFile::Section::Cells, "Int64", "offsets", 1, offsets);
    file.add(VtuFile::Section::Cells, "UInt8", "types", 1,
             std::vector<std::uint8_t>(t.size(), 5)); // VTK_TRIANGLE
    if (body.record_triangle_loads)
        file.vectors(VtuFile::Section::CellData, "force_N", body.triangle_force_N);
    file.write(path, body.worldVertices().size(), t.size());
}

/// The force chains: the grain centres as points, a line cell per touching pair.
void writeContacts(const DemSystem &system, const std::string &path) {
    const auto network = system.contactNetwork();
    VtuFile file;
    file.vectors(VtuFile::Section::Points, "position_m", system.particles().position);
    std::vector<std::int64_t> connectivity, offsets;
    std::vector<double> force;
    for (const PairForce &c : network) {
        connectivity.insert(connectivity.end(), {std::int64_t(c.i), std::int64_t(c.j)});
        offsets.push_back(std::int64_t(connectivity.size()));
        force.push_back(c.normal_force_N);
    }
    file.add(VtuFile::Section::CellData, "Float64", "normal_force_N", 1, force);
    file.add(VtuFile::Section::Cells, "Int64", "connectivity", 1, connectivity);
    file.add(VtuFile::Section::Cells, "Int64", "offsets", 1, offsets);
    file.add(VtuFile::Section::Cells, "UInt8", "types", 1,
             std::vector<std::uint8_t>(network.size(), 3)); // VTK_LINE
    file.write(path, system.particles().size(), network.size());
}

} // namespace

VtkWriter::VtkWriter(std::string directory, bool contact_network)
    : directory_(std::move(directory)), contact_network_(contact_network) {}

void VtkWriter::writeParticles(const ParticleStore &p, const std::string &path) {
    const std::size_t n = p.size();
    VtuFile file;
    file.vectors(VtuFile::Section::Points, "position_m", p.position);
    std::vector<std::int64_t> ids(p.id.begin(), p.id.end());
    file.add(VtuFile::Section::PointData, "Int64", "id", 1, ids);
    file.add(VtuFile::Section::PointData, "Float64", "radius_m", 1, p.radius);
    file.vectors(VtuFile::Section::PointData, "velocity_m_s", p.velocity);
    file.vectors(VtuFile::Section::PointData, "angular_velocity_rad_s", p.angular_velocity);
    file.vectors(VtuFile::Section::PointData, "force_N", p.force);
    // One vertex cell per grain: without cells ParaView's default (Surface) view shows nothing.
    std::vector<std::int64_t> connectivity(n), offsets(n);
    for (std::size_t i = 0; i < n; ++i) {
        connectivity[i] = std::int64_t(i);
        offsets[i] = std::int64_t(i + 1);
    }
    file.add(VtuFile::Section::Cells, "Int64", "connectivity", 1, connectivity);
    file.add(VtuFile::Section::Cells, "Int64", "offsets", 1, offsets);
    file.add(VtuFile::Section::Cells, "UInt8", "types", 1,
             std::vector<std::uint8_t>(n, 1)); // VTK_VERTEX
    file.write(path, n, n, "radius_m");
}

void VtkWriter::write(const DemSystem &system, double time_s) {
    const int index = int(times_.size());
    writeParticles(system.particles(), directory_ + "/" + numbered("particles", index));
    if (contact_network_)
        writeContacts(system, directory_ + "/" + numbered("contacts", index));
    body_names_.clear();
    for (int b = 0; b < system.bodyCount(); ++b) {
        const std::string prefix = "body_" + system.body(b).name();
        writeMesh(system.body(b), directory_ + "/" + numbered(prefix, index));
        body_names_.push_back(system.body(b).name());
    }
    times_.push_back(time_s);
    writeCollection("particles.pvd", "particles");
    if (contact_network_)
        writeCollection("contacts.pvd", "contacts");
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
