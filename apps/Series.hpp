#pragma once
// The participants' time series (soil.csv, rig.csv, mbs.csv): CSV files that a crash at any
// moment leaves readable and that a resumed run continues cleanly.
#include <optional>
#include <sstream>
#include <string>

namespace grainlink::apps {

/// One time series CSV, its first column the time [s]. Each window's rows reach the file whole,
/// in one write when the window ends (write()): a crash leaves whole rows and at most one cut
/// last line, never rows held back in a buffer.
///
/// Fresh (no `restart_s`): the header alone. Resumed at `restart_s`: the rows up to that time
/// are kept; those after it (computed after the checkpoint, lost with the crash) and any line
/// that is not a whole row (cut by a crash: no line end, another number of cells than the
/// header, no time in its first cell) are dropped. The kept rows are written to a temporary
/// file, synced and renamed over the series, so a second crash right after the resume never
/// loses them.
class Series {
public:
    Series(std::string path, const std::string &header, std::optional<double> restart_s);
    ~Series();
    Series(const Series &) = delete;
    Series &operator=(const Series &) = delete;

    /// The window's rows, each ending in '\n'; they reach the file at write().
    std::ostream &rows() { return rows_; }
    /// Appends the rows given since the last call to the file in one write.
    void write();
    /// Drops the rows given since the last write (a window repeated by implicit coupling: its
    /// rejected try's rows never reach the file).
    void discard() { rows_.str(std::string()); }

private:
    std::string path_;
    int fd_ = -1;
    std::ostringstream rows_;
};

} // namespace grainlink::apps
