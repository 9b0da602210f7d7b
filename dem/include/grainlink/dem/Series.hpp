#pragma once
// A run's time series (series.csv of `grainlink dem`, the participants' soil.csv, rig.csv,
// mbs.csv): CSV files that a crash at any moment leaves readable and that a resumed run
// continues cleanly.
#include <cstddef>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace grainlink::dem {

/// Where a resumed series restarts: the rows whose cell in `column` (0: the time [s]; a step
/// count for `grainlink dem`) is at most `last` are kept.
struct SeriesRestart {
    double last = 0.0;
    std::size_t column = 0;
};

/// One time series CSV. Rows reach the file whole, in one write at write(): a crash leaves
/// whole rows and at most one cut last line, never rows held back in a buffer.
///
/// Fresh (no restart): the header alone. Resumed: the rows up to the restart are kept; those
/// after it (computed after the checkpoint, lost with the crash) and any line that is not a
/// whole row (cut by a crash: no line end, another number of cells than the header, no number
/// in the restart column) are dropped. The kept rows are written to a temporary file, synced
/// and renamed over the series, so a second crash right after the resume never loses them.
/// A series whose header differs from this run's is refused (another run's file).
class Series {
public:
    Series(std::string path, const std::string &header, std::optional<SeriesRestart> restart);
    ~Series();
    Series(const Series &) = delete;
    Series &operator=(const Series &) = delete;

    /// The rows to come, each ending in '\n'; they reach the file at write().
    std::ostream &rows() { return rows_; }
    /// Appends the rows given since the last call to the file in one write; a failed write
    /// (a full disk) throws, naming the file and the reason.
    void write();
    /// Drops the rows given since the last write (a window repeated by implicit coupling: its
    /// rejected try's rows never reach the file).
    void discard() { rows_.str(std::string()); }

private:
    std::string path_;
    int fd_ = -1;
    std::ostringstream rows_;
};

/// Every column of a series written by Series, by its header's name (cells read with strtod:
/// "nan" and subnormal numbers too). A row with another number of cells than the header is an
/// error naming the file.
std::map<std::string, std::vector<double>> readSeries(const std::string &path);

} // namespace grainlink::dem
