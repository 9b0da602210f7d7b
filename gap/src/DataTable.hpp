#pragma once
// One reader of a measurement's data file, for the diagnosis and the importers alike: a table
// as spreadsheets and other codes write it (docs/gap.md, "The measurements folder").
#include <optional>
#include <string>
#include <vector>

namespace grainlink::gap {

/// How a data file is written: `data.comment`, `data.delimiter`, `data.decimal`, `data.columns`.
struct TableFormat {
    std::string comment = "#"; ///< lines starting with it are skipped; "" skips none
    char delimiter = ',';
    bool blanks = false; ///< cells separated by runs of blanks (`delimiter: whitespace`)
    char decimal = '.';  ///< ',' for a European spreadsheet's numbers (with `delimiter: ";"`)
    /// The column names of a file without a header line (another code's output, whose names
    /// stand on a comment line): every line not a comment is then a row.
    std::vector<std::string> columns;
    /// The line under the header holds units (a spreadsheet's "mm;kPa"): skipped.
    bool units_row = false;
    /// Lines before the header (an instrument's title and preamble), skipped whatever they hold.
    int skip_lines = 0;

    /// Cells separated by ",", ";", "tab" or "whitespace" (runs of blanks).
    void delimitedBy(const std::string &name) {
        blanks = name == "whitespace";
        delimiter = name == "tab" ? '\t' : blanks ? ' ' : name.empty() ? ',' : name[0];
    }
};

/// A data file's header names and rows of text cells, with the file line of every row.
struct DataTable {
    std::string file;
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::vector<int> lines;
    char decimal = '.';
    char delimiter = ',';
    bool header_given = false; ///< the names came from data.columns, not from the file
    /// The last comment line above the header: another code's column names (LIGGGHTS').
    std::string names_comment;
    /// The row of units under the header (`units_row`), and its line; empty without one.
    std::vector<std::string> units;
    int units_line = 0;

    /// The column of that name; none when it is missing. Throws when two columns share it.
    std::optional<std::size_t> find(const std::string &name) const;
    /// The header's names quoted and comma-separated, for a message: 'Sinkage, mm', 'Comment'.
    std::string names() const;
    /// Why no column is named `name`: the file, its columns, and the likely cause (another
    /// delimiter, names on a comment line).
    std::string missingColumn(const std::string &name) const;
    /// Whether row r holds no value in column c (empty, NaN, NA, N/A, #N/A, null, none, "-",
    /// "--"; or no such cell).
    bool missing(std::size_t row, std::size_t col) const;
    /// Row r's cell in column c; a cell that is not a finite number is an error naming the
    /// file, line and column.
    double number(std::size_t row, std::size_t col) const;
};

/// Where the units row gives column `col` another unit than `unit` (of `dimension`): the
/// file, the row's line and both units; "" where it agrees, is absent, or holds no unit of
/// that kind ("-", a word): a column declared in m whose file says mm reads 1000 times too deep.
std::string unitsRowDisagreement(const DataTable &table, std::size_t col, const std::string &unit,
                                 const std::string &dimension);

/// File lines for a message: the first five, comma-separated, then ", ..." ("6, 7, 9").
std::string lineList(const std::vector<int> &lines);

/// Names quoted and comma-separated ('Sinkage, mm', 'Pressure, kPa'): a name holding a comma
/// or a blank reads as one name. Every list of columns in a message is written by it.
std::string quotedNames(const std::vector<std::string> &names);

/// Splits one line into cells: quoted cells may hold the delimiter ("Sinkage, mm") and a
/// doubled quote; blanks around a cell are dropped.
std::vector<std::string> splitCells(const std::string &line, const TableFormat &format);

/// Reads `path`; throws config::ConfigError naming the file when it cannot be read, is empty,
/// has no header or no data rows.
DataTable readDataTable(const std::string &path, const TableFormat &format);

} // namespace grainlink::gap
