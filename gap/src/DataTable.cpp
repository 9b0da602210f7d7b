#include "DataTable.hpp"

#include "grainlink/gap/Experiments.hpp"

#include "grainlink/config/Number.hpp"

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

/// A delimiter as experiments.yaml writes it.
std::string delimiterName(char c) {
    return c == '\t' ? "tab" : c == ' ' ? "whitespace" : "\"" + std::string(1, c) + "\"";
}

/// The delimiter a header read as one cell holds in its place (';' or a tab); 0: none.
char otherDelimiter(const DataTable &t) {
    if (t.header_given || t.header.size() != 1)
        return 0;
    for (char c : {';', '\t', ','})
        if (c != t.delimiter && t.header[0].find(c) != std::string::npos)
            return c;
    return 0;
}

/// Whether a header's cells all read as numbers: the first row of a file whose names stand on
/// a comment line.
bool numericHeader(const DataTable &t) {
    return !t.header_given &&
           std::all_of(t.header.begin(), t.header.end(),
                       [](const std::string &h) { return config::wholeNumber(h).has_value(); });
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

std::string quotedNames(const std::vector<std::string> &names) {
    std::string list;
    for (const auto &n : names)
        list += (list.empty() ? "'" : ", '") + n + "'";
    return list;
}

std::string DataTable::names() const {
    return quotedNames(header);
}

std::string DataTable::missingColumn(const std::string &name) const {
    std::string why = "column '" + name + "' is not in " + file + " (its columns: " + names() + ")";
    if (const char other = otherDelimiter(*this))
        return why + "; its header reads as one column holding " + delimiterName(other) +
               ": give data.delimiter: " + delimiterName(other);
    if (!header_given && header.size() == 1 && header[0].find(' ') != std::string::npos)
        return why + "; its cells may be separated by blanks: give data.delimiter: whitespace";
    if (numericHeader(*this)) {
        // The names stand on a comment line ("# TimeStep v_z v_f"): said as a list to copy.
        std::string list;
        TableFormat words;
        words.delimitedBy("whitespace");
        const std::size_t mark = names_comment.find_first_not_of("#%;/ \t");
        if (mark != std::string::npos)
            for (const std::string &w : splitCells(names_comment.substr(mark), words))
                list += (list.empty() ? "" : ", ") + w;
        return why + "; its first line read holds numbers: a file whose column names stand on a " +
               "comment line? give data.columns" + (list.empty() ? "" : ": [" + list + "]");
    }
    return why;
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
    t.delimiter = format.blanks ? ' ' : format.delimiter;
    t.header = format.columns;
    t.header_given = !format.columns.empty();
    bool units_row = format.units_row && !t.header_given;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        if (++number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0)
            line.erase(0, 3); // a spreadsheet's byte-order mark
        if (number <= format.skip_lines)
            continue;
        if (!format.comment.empty() && line.rfind(format.comment, 0) == 0) {
            if (t.header.empty())
                t.names_comment = line.substr(format.comment.size());
            continue;
        }
        if (trimmed(line).empty())
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
            t.units = std::move(cells);
            t.units_line = number;
            continue;
        }
        // More cells than columns: a delimiter inside a number (0,5 in a comma-separated
        // file), a title line read as the header, or data.columns naming too few. Cells would
        // be read under the wrong names. Trailing empty cells (a trailing delimiter) are no cells.
        while (cells.size() > t.header.size() && cells.back().empty())
            cells.pop_back();
        if (cells.size() > t.header.size() || (t.header_given && cells.size() < t.header.size())) {
            std::string why;
            if (t.header_given)
                why = "name every column of the file, in order";
            else if (const char other = otherDelimiter(t))
                why = "the header reads as one column holding " + delimiterName(other) +
                      ": give data.delimiter: " + delimiterName(other);
            else if (t.header.size() == 1)
                why = "a title above the header? give data.skip_lines (the lines before the "
                      "header) or start it with data.comment";
            else if (format.decimal == format.delimiter && !format.blanks)
                why = "with a decimal comma in a comma-separated file, quote each number (\"0,5\")";
            else if (format.delimiter == ',' && !format.blanks)
                why = "a decimal comma in a comma-separated file? give data.delimiter and "
                      "data.decimal";
            else
                why = "a stray cell, or a header naming too few columns";
            throw config::ConfigError(
                path + ":" + std::to_string(number) + ": " + std::to_string(cells.size()) +
                " cells where " +
                (t.header_given ? "data.columns names " : "the header line names ") +
                std::to_string(t.header.size()) + " (" + t.names() + "): " + why);
        }
        t.rows.push_back(std::move(cells));
        t.lines.push_back(number);
    }
    if (number == 0)
        throw config::ConfigError("data file " + path + " is empty");
    if (number <= format.skip_lines)
        throw config::ConfigError("data file " + path + " has " + std::to_string(number) +
                                  " line(s), none after the " + std::to_string(format.skip_lines) +
                                  " of data.skip_lines");
    if (t.header.empty())
        throw config::ConfigError("data file " + path + " has no header line (its " +
                                  std::to_string(number) + " line(s) are comments or blank)");
    if (t.rows.empty())
        throw config::ConfigError("data file " + path + " has no data rows");
    return t;
}

std::string unitsRowDisagreement(const DataTable &table, std::size_t col, const std::string &unit,
                                 const std::string &dimension) {
    if (col >= table.units.size())
        return "";
    // "[mm]", "(kPa)", " mm ": the unit inside.
    std::string cell = trimmed(table.units[col]);
    if (cell.size() >= 2 && (cell.front() == '[' || cell.front() == '(') &&
        (cell.back() == ']' || cell.back() == ')'))
        cell = trimmed(cell.substr(1, cell.size() - 2));
    double row = 0.0, given = 0.0;
    try {
        row = unitFactor(cell, dimension);
        given = unitFactor(unit, dimension);
    } catch (const std::invalid_argument &) {
        return ""; // not a unit of this kind: the row says nothing to check
    }
    if (std::abs(row - given) <= 1e-9 * std::abs(given))
        return "";
    return table.file + ":" + std::to_string(table.units_line) + ": the units row gives column '" +
           table.header[col] + "' in '" + cell + "', but it is read in '" + unit + "'";
}

std::string lineList(const std::vector<int> &lines) {
    std::string list;
    for (std::size_t i = 0; i < lines.size() && i < 5; ++i)
        list += (i ? ", " : "") + std::to_string(lines[i]);
    return list + (lines.size() > 5 ? ", ..." : "");
}

} // namespace grainlink::gap
