#include "grainlink/study/ResultTable.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include "grainlink/study/StudyFolder.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

namespace grainlink::study {

using nlohmann::json;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string number(double v, const char *format = "%.10g") {
    if (std::isnan(v))
        return "";
    char text[40];
    std::snprintf(text, sizeof text, format, v);
    return text;
}

/// A CSV field: quoted when it holds a comma, a quote or a space.
std::string field(const std::string &text) {
    if (text.find_first_of(",\" ") == std::string::npos)
        return text;
    std::string quoted = "\"";
    for (char c : text)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

std::string settingOf(const Point &p, const std::string &key) {
    for (const auto &[k, v] : p.settings)
        if (k == key)
            return v;
    return "";
}

const char *statusName(PointStatus s) {
    return s == PointStatus::Done ? "done" : s == PointStatus::Failed ? "failed" : "unfinished";
}

} // namespace

std::optional<double> observable(const json &summary, const std::string &path) {
    const json *node = &summary;
    std::istringstream steps(path);
    for (std::string step; std::getline(steps, step, '.');) {
        if (node->is_object()) {
            const auto it = node->find(step);
            if (it == node->end())
                return std::nullopt;
            node = &*it;
        } else if (const auto k = config::listIndex(step);
                   node->is_array() && k && *k < node->size()) {
            node = &(*node)[*k];
        } else {
            return std::nullopt;
        }
    }
    if (!node->is_number())
        return std::nullopt;
    return node->get<double>();
}

Statistics statistics(const std::vector<double> &values) {
    Statistics s;
    s.n = values.size();
    if (s.n == 0) {
        s.mean = s.sd = s.sem = kNaN;
        return s;
    }
    double sum = 0.0;
    for (double v : values)
        sum += v;
    s.mean = sum / double(s.n);
    if (s.n < 2) {
        s.sd = s.sem = kNaN;
        return s;
    }
    double squares = 0.0;
    for (double v : values)
        squares += (v - s.mean) * (v - s.mean);
    s.sd = std::sqrt(squares / double(s.n - 1));
    s.sem = s.sd / std::sqrt(double(s.n));
    return s;
}

std::vector<TableRow> tableRows(const Study &study, const std::vector<PointResult> &results) {
    std::vector<TableRow> rows;
    std::vector<std::vector<std::vector<double>>> values; // row, observable, replicate
    std::map<std::vector<std::string>, std::size_t> row_of;
    for (const PointResult &r : results) {
        std::vector<std::string> settings;
        for (const std::string &key : study.varied_keys)
            settings.push_back(settingOf(r.point, key));
        const auto [it, added] = row_of.emplace(settings, rows.size());
        if (added) {
            rows.push_back({settings, 0, 0, {}});
            values.emplace_back(study.observables.size());
        }
        TableRow &row = rows[it->second];
        ++row.points;
        if (r.status != PointStatus::Done)
            continue;
        ++row.finished;
        for (std::size_t o = 0; o < study.observables.size(); ++o)
            if (const auto v = observable(r.summary, study.observables[o]))
                values[it->second][o].push_back(*v);
    }
    for (std::size_t k = 0; k < rows.size(); ++k)
        for (const auto &v : values[k])
            rows[k].observables.push_back(statistics(v));
    return rows;
}

std::string markdownTable(const Study &study, const std::vector<TableRow> &rows) {
    std::ostringstream md;
    md << "|";
    for (const std::string &key : study.varied_keys)
        md << ' ' << key << " |";
    md << " finished |";
    for (const std::string &o : study.observables)
        md << ' ' << o << " |";
    md << "\n|";
    for (std::size_t k = 0; k < study.varied_keys.size() + 1 + study.observables.size(); ++k)
        md << "---|";
    md << '\n';
    for (const TableRow &row : rows) {
        md << "|";
        for (const std::string &s : row.settings)
            md << ' ' << s << " |";
        md << ' ' << row.finished << '/' << row.points << " |";
        for (const Statistics &s : row.observables) {
            if (s.n == 0)
                md << " - |";
            else if (s.n == 1)
                md << ' ' << number(s.mean, "%.6g") << " |";
            else
                md << ' ' << number(s.mean, "%.6g") << " ± " << number(s.sem, "%.2g") << " (sd "
                   << number(s.sd, "%.2g") << ", n " << s.n << ") |";
        }
        md << '\n';
    }
    if (!study.replicate_key.empty())
        md << "\nmean ± standard error over the replicates (" << study.replicate_key
           << "), sd: standard deviation, n: finished replicates\n";
    return md.str();
}

TableFiles writeTables(const Study &study, const std::vector<PointResult> &results) {
    const StudyFolder folder(study.directory);
    TableFiles files;
    files.points_csv = folder.directory() + "/points.csv";
    files.table_csv = folder.directory() + "/table.csv";
    files.table_md = folder.directory() + "/table.md";

    std::ostringstream points;
    points << "id,label,status";
    for (const std::string &key : study.varied_keys)
        points << ',' << field(key);
    if (!study.replicate_key.empty())
        points << ',' << field(study.replicate_key);
    for (const std::string &o : study.observables)
        points << ',' << field(o);
    points << ",wall_s,folder,error\n";
    for (const PointResult &r : results) {
        points << r.point.id << ',' << field(r.point.label) << ',' << statusName(r.status);
        for (const std::string &key : study.varied_keys)
            points << ',' << field(settingOf(r.point, key));
        if (!study.replicate_key.empty())
            points << ',' << field(settingOf(r.point, study.replicate_key));
        for (const std::string &o : study.observables) {
            const auto v = r.status == PointStatus::Done ? observable(r.summary, o) : std::nullopt;
            if (r.status == PointStatus::Done && !v)
                files.warnings.push_back("point " + r.point.id + " (" + r.point.label +
                                         "): no number at '" + o + "' in " + r.folder + "/" +
                                         r.point.kind.summary_file);
            points << ',' << (v ? number(*v) : "");
        }
        points << ',' << (r.status == PointStatus::Done ? number(r.wall_s, "%.3f") : "") << ','
               << field(r.folder) << ',' << field(r.error) << '\n';
    }
    writeFileAtomically(files.points_csv, points.str());

    const std::vector<TableRow> rows = tableRows(study, results);
    std::ostringstream table;
    for (const std::string &key : study.varied_keys)
        table << field(key) << ',';
    table << "points,finished";
    for (const std::string &o : study.observables)
        table << ',' << field(o + ":mean") << ',' << field(o + ":sd") << ',' << field(o + ":sem")
              << ',' << field(o + ":n");
    table << '\n';
    for (const TableRow &row : rows) {
        for (const std::string &s : row.settings)
            table << field(s) << ',';
        table << row.points << ',' << row.finished;
        for (const Statistics &s : row.observables)
            table << ',' << number(s.mean) << ',' << number(s.sd) << ',' << number(s.sem) << ','
                  << s.n;
        table << '\n';
    }
    writeFileAtomically(files.table_csv, table.str());
    writeFileAtomically(files.table_md, markdownTable(study, rows));
    return files;
}

} // namespace grainlink::study
