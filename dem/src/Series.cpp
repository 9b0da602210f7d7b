#include "grainlink/dem/Series.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

namespace grainlink::dem {

namespace {

std::runtime_error systemError(const std::string &what, const std::string &path) {
    return std::runtime_error(what + " " + path + ": " + std::strerror(errno));
}

/// Writes all of `text` to `fd` (a write may take only part of it).
void writeAll(int fd, const std::string &text, const std::string &path) {
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            throw systemError("cannot write", path);
        done += std::size_t(n);
    }
}

std::size_t cells(const std::string &line) {
    std::size_t n = 1;
    for (const char c : line)
        n += c == ',';
    return n;
}

/// The header and the whole rows of the series at `path` up to the restart, as a file's text.
std::string keptPrefix(const std::string &path, const std::string &header,
                       const SeriesRestart &restart) {
    std::string kept = header + '\n';
    std::ifstream in(path);
    std::string line;
    if (!std::getline(in, line))
        return kept; // no series yet, or an empty one: nothing to keep
    if (line != header)
        throw std::runtime_error(path + ": its columns differ from this run's (" +
                                 line.substr(0, 60) + "...): cannot resume");
    const std::size_t columns = cells(header);
    while (std::getline(in, line)) {
        if (in.eof())
            break; // no line end: a row cut by the crash
        if (cells(line) != columns)
            continue;
        std::size_t start = 0;
        for (std::size_t c = 0; c < restart.column; ++c)
            start = line.find(',', start) + 1;
        const std::string cell = line.substr(start, line.find(',', start) - start);
        char *end = nullptr;
        const double value = std::strtod(cell.c_str(), &end);
        const bool whole = !cell.empty() && *end == '\0' && std::isfinite(value);
        if (whole && value <= restart.last + 1e-12 * std::max(1.0, std::abs(restart.last)))
            kept += line + '\n';
    }
    return kept;
}

} // namespace

Series::Series(std::string path, const std::string &header, std::optional<SeriesRestart> restart)
    : path_(std::move(path)) {
    if (restart && restart->column >= cells(header))
        throw std::logic_error("Series: restart column beyond the header of " + path_);
    const std::string prefix = restart ? keptPrefix(path_, header, *restart) : header + '\n';
    const std::string partial = path_ + ".partial";
    const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        throw systemError("cannot create", partial);
    try {
        writeAll(fd, prefix, partial);
        if (::fsync(fd) != 0)
            throw systemError("cannot sync", partial);
    } catch (...) {
        ::close(fd);
        throw;
    }
    ::close(fd);
    if (std::rename(partial.c_str(), path_.c_str()) != 0)
        throw systemError("cannot rename " + partial + " to", path_);
    fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0)
        throw systemError("cannot open", path_);
    rows_.precision(10);
}

Series::~Series() {
    if (fd_ >= 0)
        ::close(fd_);
}

void Series::write() {
    const std::string text = rows_.str();
    if (text.empty())
        return;
    writeAll(fd_, text, path_);
    rows_.str(std::string());
}

std::map<std::string, std::vector<double>> readSeries(const std::string &path) {
    std::ifstream in(path);
    std::string line;
    if (!std::getline(in, line))
        throw std::runtime_error("cannot read the series " + path);
    std::vector<std::string> header;
    std::stringstream header_stream(line);
    for (std::string cell; std::getline(header_stream, cell, ',');)
        header.push_back(cell);
    std::vector<std::vector<double>> columns(header.size());
    while (std::getline(in, line)) {
        std::size_t c = 0;
        std::stringstream row(line);
        for (std::string cell; std::getline(row, cell, ','); ++c)
            if (c < header.size())
                columns[c].push_back(std::strtod(cell.c_str(), nullptr));
        if (c != header.size())
            throw std::runtime_error(path + ": a row with " + std::to_string(c) +
                                     " cells under a header of " + std::to_string(header.size()));
    }
    std::map<std::string, std::vector<double>> named;
    for (std::size_t c = 0; c < header.size(); ++c)
        named[header[c]] = std::move(columns[c]);
    return named;
}

} // namespace grainlink::dem
