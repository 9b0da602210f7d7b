#include "DataTable.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>

namespace grainlink::gap {

namespace {

bool blank(char c) {
    return c == ' ' || c == '\t' || c == '\r';
}

std::string trimmed(const std::string &s) {
    std::size_t a = 0, b = s.size();
    while (a < b && blank(s[a]))
        ++a;
    while (b > a && blank(s[b - 1]))
        --b;
    return s.substr(a, b - a);
}

/// Whether `cell` is written as a decimal number: digits, one sign, one decimal mark `decimal`
/// and an exponent. strtod alone would also take "0x10" as 16 and, with the decimal mark
/// swapped in, "1.000" (a thousands separator beside a decimal comma) as 1.
bool decimalNumber(const std::string &cell, char decimal) {
    for (char c : cell)
        if (!(std::isdigit(static_cast<unsigned char>(c)) || c == decimal || c == '+' || c == '-' ||
              c == 'e' || c == 'E'))
            return false;
    return true;
}

/// A cell that holds no value: empty, or a missing-value mark of a spreadsheet or of numpy.
bool missingCell(const std::string &cell) {
    std::string low;
    for (char c : cell)
        low += char(std::tolower(static_cast<unsigned char>(c)));
    return low.empty() || low == "nan" || low == "-nan" || low == "na" || low == "n/a" ||
           low == "#n/a" || low == "null" || low == "none" || low == "-" || low == "--";
}

} // namespace

std::vector<std::string> splitCells(const std::string &line, const TableFormat &format) {
    std::vector<std::string> out;
    std::string cell;
    bool quoted = false;   // inside a quoted stretch
    bool had_text = false; // this cell has begun (for runs of blanks)
    const auto push = [&] {
        out.push_back(trimmed(cell));
        cell.clear();
        had_text = false;
    };
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (c == '"') {
            if (quoted && i + 1 < line.size() && line[i + 1] == '"') {
                cell += '"'; // a doubled quote inside quotes
                ++i;
            } else {
                quoted = !quoted;
            }
            had_text = true;
            continue;
        }
        const bool split = !quoted && (format.blanks ? blank(c) : c == format.delimiter);
        if (!split) {
            cell += c;
            had_text = had_text || !blank(c);
            continue;
        }
        if (!format.blanks || had_text)
            push();
    }
    if (!format.blanks || had_text)
        push();
    return out;
}

std::optional<std::size_t> DataTable::find(const std::string &name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end())
        return std::nullopt;
    if (std::find(it + 1, header.end(), name) != header.end())
        throw config::ConfigError(file + ": two columns are named '" + name +
                                  "': rename one in the file's header");
    return std::size_t(it - header.begin());
}

std::string DataTable::names() const {
    std::string have;
    for (const auto &h : header)
        have += (have.empty() ? "" : ", ") + h;
    return have;
}

bool DataTable::missing(std::size_t row, std::size_t col) const {
    return col >= rows[row].size() || missingCell(rows[row][col]);
}

double DataTable::number(std::size_t row, std::size_t col) const {
    const std::string as_written = col < rows[row].size() ? rows[row][col] : std::string();
    std::string cell = as_written;
    std::replace(cell.begin(), cell.end(), decimal, '.');
    char *end = nullptr;
    const double v = std::strtod(cell.c_str(), &end);
    if (cell.empty() || !decimalNumber(as_written, decimal) || end != cell.c_str() + cell.size() ||
        !std::isfinite(v)) {
        const bool comma = decimal == '.' && as_written.find(',') != std::string::npos;
        const bool dot = decimal == ',' && as_written.find('.') != std::string::npos;
        // A word in the first row of a file with a header: most often a row of units.
        const bool units =
            row == 0 && !header_given &&
            !std::isdigit(static_cast<unsigned char>(as_written.empty() ? 'x' : as_written[0]));
        throw config::ConfigError(
            file + ":" + std::to_string(lines[row]) + ": column '" + header[col] + "': '" +
            as_written + "' is not a finite number" +
            (comma ? " (numbers with a decimal comma: give data.decimal: \",\")" : "") +
            (dot ? " (data.decimal is \",\": a '.' would be a thousands separator; write the "
                   "numbers without one)"
                 : "") +
            (units ? " (a row of units under the header? give data.units_row: true)" : ""));
    }
    return v;
}

DataTable readDataTable(const std::string &path, const TableFormat &format) {
    std::ifstream in(path);
    if (!in)
        throw config::ConfigError("cannot read data file " + path);
    DataTable t;
    t.file = path;
    t.decimal = format.decimal;
    t.header = format.columns;
    t.header_given = !format.columns.empty();
    bool units_row = format.units_row && !t.header_given;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        if (++number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0)
            line.erase(0, 3); // a spreadsheet's byte-order mark
        if (trimmed(line).empty() ||
            (!format.comment.empty() && line.rfind(format.comment, 0) == 0))
            continue;
        std::vector<std::string> cells = splitCells(line, format);
        if (std::all_of(cells.begin(), cells.end(), [](const std::string &c) { return c.empty(); }))
            continue; // a spreadsheet's row of empty cells
        if (t.header.empty()) {
            t.header = std::move(cells);
            continue;
        }
        if (units_row) {
            units_row = false;
            continue;
        }
        // More cells than columns: a delimiter inside a number (0,5 in a comma-separated
        // file), or data.columns naming too few. Cells would be read under the wrong names.
        // Trailing empty cells (a trailing delimiter) are no cells.
        while (cells.size() > t.header.size() && cells.back().empty())
            cells.pop_back();
        if (cells.size() > t.header.size() || (t.header_given && cells.size() < t.header.size()))
            throw config::ConfigError(
                path + ":" + std::to_string(number) + ": " + std::to_string(cells.size()) +
                " cells where " +
                (t.header_given ? "data.columns names " : "the header line names ") +
                std::to_string(t.header.size()) + " (" + t.names() + ")" +
                (format.decimal == format.delimiter && !format.blanks
                     ? ": with a decimal comma in a comma-separated file, quote each number "
                       "(\"0,5\")"
                 : t.header_given ? ": name every column of the file, in order"
                                  : ": a decimal comma in a comma-separated file? give "
                                    "data.delimiter and data.decimal"));
        t.rows.push_back(std::move(cells));
        t.lines.push_back(number);
    }
    if (t.header.empty())
        throw config::ConfigError("data file " + path + " has no header line");
    if (t.rows.empty())
        throw config::ConfigError("data file " + path + " has no data rows");
    return t;
}

} // namespace grainlink::gap
