#include "grainlink/gap/Importers.hpp"

#include "grainlink/gap/Experiments.hpp"

#include "DataTable.hpp"

#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/config/Number.hpp"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace grainlink::gap {

namespace fs = std::filesystem;

namespace {

DataTable readCsv(const fs::path &path) {
    return readDataTable(path.string(), TableFormat{});
}

/// The column `name` of `c`; a missing one is an error naming the file and its columns.
std::size_t column(const DataTable &c, const std::string &name) {
    if (const auto col = c.find(name))
        return *col;
    throw config::ConfigError(c.missingColumn(name));
}

/// Writes the named columns of `c` to `path` (a copy of just what the folder uses).
void writeColumns(const DataTable &c, const std::vector<std::string> &names, const fs::path &source,
                  const fs::path &path, const std::string &comment) {
    std::vector<std::size_t> cols;
    for (const auto &n : names)
        cols.push_back(column(c, n));
    std::ofstream out(path);
    out << "# " << comment << "\n# copied from " << source.string() << "\n";
    for (std::size_t i = 0; i < names.size(); ++i) {
        const bool quote = names[i].find_first_of(",\"") != std::string::npos;
        std::string name;
        for (char ch : names[i])
            name += ch == '"' ? std::string("\"\"") : std::string(1, ch);
        out << (i ? "," : "") << (quote ? "\"" + name + "\"" : name);
    }
    out << '\n';
    for (std::size_t r = 0; r < c.rows.size(); ++r) {
        for (std::size_t i = 0; i < cols.size(); ++i) {
            std::string cell = c.missing(r, cols[i]) ? "" : c.rows[r][cols[i]];
            std::replace(cell.begin(), cell.end(), c.decimal, '.'); // 0,5 beside ';'
            out << (i ? "," : "") << cell;
        }
        out << '\n';
    }
    if (!out)
        throw std::runtime_error(path.string() + ": cannot write");
}

YAML::Node loadOrNew(const fs::path &file, const std::string &name) {
    if (fs::exists(file))
        return YAML::LoadFile(file.string());
    YAML::Node root;
    root["name"] = name;
    root["experiments"] = YAML::Node(YAML::NodeType::Sequence);
    return root;
}

/// Every number in `node` written with 15 significant digits where that reads back as the same
/// double: yaml-cpp writes 17 (0.058000000000000003), exact but not as the user wrote it.
void shortenNumbers(YAML::Node node) {
    if (node.IsScalar()) {
        const std::string text = node.Scalar();
        char *end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (!text.empty() && end == text.c_str() + text.size() && std::isfinite(v) &&
            text.find_first_of("xX") == std::string::npos) {
            char shorter[32];
            std::snprintf(shorter, sizeof shorter, "%.15g", v);
            if (std::strtod(shorter, nullptr) == v)
                node = std::string(shorter);
        }
        return;
    }
    if (node.IsSequence())
        for (YAML::Node child : node)
            shortenNumbers(child);
    else if (node.IsMap())
        for (auto it = node.begin(); it != node.end(); ++it)
            shortenNumbers(it->second);
}

void save(YAML::Node root, const fs::path &file, const std::string &header) {
    shortenNumbers(root);
    YAML::Emitter e;
    e << root;
    const fs::path tmp = file.string() + ".tmp";
    {
        std::ofstream out(tmp);
        out << header << e.c_str() << '\n';
        if (!out)
            throw std::runtime_error(tmp.string() + ": cannot write");
    }
    fs::rename(tmp, file);
}

YAML::Node flow(YAML::Node n) {
    n.SetStyle(YAML::EmitterStyle::Flow);
    return n;
}

} // namespace

std::vector<std::string> importCmu(const std::string &cmu_directory, const std::string &out,
                                   const CmuImportOptions &options) {
    const fs::path src(cmu_directory), dst(out);
    if (!fs::is_directory(src / "plates") && !fs::is_directory(src / "steady_state_wheel"))
        throw std::runtime_error(cmu_directory + ": not the CMU 3d-terramechanics folder (no "
                                                 "plates/ or steady_state_wheel/)");
    const std::map<std::string, std::string> sinkage_columns{
        {"synced", "sinkage_synced_m"},
        {"authors", "sinkage_m"},
        {"deflection_corrected", "sinkage_synced_deflcorr_m"}};
    if (!sinkage_columns.count(options.sinkage))
        throw std::invalid_argument("sinkage column '" + options.sinkage +
                                    "': use synced, authors or deflection_corrected");
    fs::create_directories(dst / "data");
    YAML::Node root;
    root["name"] = "cmu-3d-terramechanics";
    YAML::Node list(YAML::NodeType::Sequence);
    std::vector<std::string> ids;

    if (options.plates && fs::is_directory(src / "plates")) {
        // plate_<box>_d<DDD>mm_force-displacement_<N>.csv: one experiment per box and size.
        const std::regex name(R"(plate_(large|small)_d(\d{3})mm_force-displacement_(\d+)\.csv)");
        std::map<std::pair<std::string, int>, std::vector<fs::path>> groups;
        for (const auto &entry : fs::directory_iterator(src / "plates")) {
            std::smatch m;
            const std::string f = entry.path().filename().string();
            if (std::regex_match(f, m, name))
                groups[{m[1], std::stoi(m[2])}].push_back(entry.path());
        }
        const std::string zcol = sinkage_columns.at(options.sinkage);
        for (auto &[key, files] : groups) {
            std::sort(files.begin(), files.end());
            const std::string id = key.first + "_d" + (key.second < 100 ? "0" : "") +
                                   std::to_string(key.second);
            YAML::Node e;
            e["id"] = id;
            e["type"] = "plate_sinkage";
            YAML::Node cond;
            cond["plate_diameter_m"] = key.second / 1000.0;
            cond["box"] = key.first;
            // The carriage's median descent speed over the trials (quasi-static, not constant).
            double speed = 0.0;
            int speeds = 0;
            YAML::Node copies(YAML::NodeType::Sequence);
            for (const fs::path &f : files) {
                const fs::path json = fs::path(f).replace_extension(".json");
                if (fs::exists(json)) {
                    // The trial's metadata: its descent speed, if it gives one.
                    try {
                        std::ifstream in(json);
                        const nlohmann::json j = nlohmann::json::parse(in);
                        if (j.is_object() && j.contains("processing") &&
                            j["processing"].is_object())
                            for (const auto &[key, value] : j["processing"].items())
                                if (key.rfind("descent_speed_in_window_mm_per_s", 0) == 0 &&
                                    value.is_array() && value.size() == 3 &&
                                    value[1].is_number()) {
                                    speed += value[1].get<double>() / 1000.0;
                                    ++speeds;
                                }
                    } catch (const nlohmann::json::exception &e) {
                        throw std::runtime_error(json.string() + ": not readable JSON (" +
                                                 e.what() + ")");
                    }
                }
                const std::string copy = "data/" + f.filename().string();
                writeColumns(readCsv(f), {zcol, "pressure_synced_kPa", "force_N"}, f, dst / copy,
                             "CMU 3d-terramechanics plate test (MIT licence, (c) 2022 Catherine "
                             "Pavlov, CMU), box " + key.first + ", plate " +
                                 std::to_string(key.second) + " mm");
                copies.push_back(copy);
            }
            if (speeds > 0)
                cond["speed_m_s"] = speed / speeds;
            e["conditions"] = flow(cond);
            YAML::Node data;
            data["files"] = flow(copies);
            YAML::Node x;
            x["column"] = zcol;
            x["unit"] = "m";
            data["x"] = flow(x);
            YAML::Node y, p;
            p["column"] = "pressure_synced_kPa";
            p["unit"] = "kPa";
            y["pressure_Pa"] = flow(p);
            data["y"] = y;
            e["data"] = data;
            YAML::Node zero;
            zero["method"] = "as_recorded"; // the authors' hand-picked first contact
            e["zero"] = flow(zero);
            // Data README section 6: the zero is good to about 0.5 mm; the force zeros are
            // stale by up to about 2 N of 100-350 N.
            YAML::Node u;
            u["x_zero_sigma"] = 0.0005;
            u["x_unit"] = "m";
            u["y_relative"] = 0.01;
            u["repeats"] = "rebuilt_bed";
            e["uncertainty"] = flow(u);
            list.push_back(e);
            ids.push_back(id);
        }
    }

    if (options.wheels && fs::is_directory(src / "steady_state_wheel")) {
        for (const std::string wheel : {"smooth", "grouser"}) {
            const fs::path f = src / "steady_state_wheel" / (wheel + ".csv");
            if (!fs::exists(f))
                continue;
            const DataTable c = readCsv(f);
            const std::size_t beta_col = column(c, "beta_deg");
            const auto beta_of = [&](std::size_t r) {
                return int(std::lround(c.number(r, beta_col)));
            };
            std::vector<int> betas;
            for (std::size_t r = 0; r < c.rows.size(); ++r)
                betas.push_back(beta_of(r));
            std::sort(betas.begin(), betas.end());
            betas.erase(std::unique(betas.begin(), betas.end()), betas.end());
            const std::string copy = "data/wheel_" + wheel + ".csv";
            writeColumns(c, {"beta_deg", "slip", "F_tractive_N", "F_side_N", "F_load_N", "Z_mm"}, f,
                         dst / copy,
                         "CMU 3d-terramechanics steady-state wheel tests (MIT licence, (c) 2022 "
                         "Catherine Pavlov, CMU), " + wheel + " wheel; Z_mm with the authors' "
                         "31.5 mm offset convention");
            const std::size_t load_col = column(c, "F_load_N");
            for (int beta : betas) {
                const std::string id = wheel + "_beta" + std::to_string(beta);
                // The load the carriage put on the wheel: the runs' mean measured F_load (the
                // lab's wheel test holds it with a servo).
                double load = 0.0;
                int runs = 0;
                for (std::size_t r = 0; r < c.rows.size(); ++r)
                    if (beta_of(r) == beta) {
                        load += c.number(r, load_col);
                        ++runs;
                    }
                YAML::Node e;
                e["id"] = id;
                e["type"] = "wheel_steady_state";
                YAML::Node cond;
                cond["wheel"] = wheel;
                cond["wheel_radius_m"] = 0.058; // to the grouser base
                cond["wheel_width_m"] = 0.05;
                cond["grouser_height_m"] = wheel == "grouser" ? 0.005 : 0.0;
                cond["slip_angle_deg"] = double(beta);
                cond["carriage_speed_m_s"] = 0.01;
                cond["load_N"] = std::round(100.0 * load / runs) / 100.0;
                e["conditions"] = flow(cond);
                YAML::Node data;
                data["files"] = flow(YAML::Node(std::vector<std::string>{copy}));
                data["scatter"] = true;
                YAML::Node filter;
                filter["beta_deg"] = beta;
                data["filter"] = flow(filter);
                YAML::Node x;
                x["column"] = "slip";
                x["unit"] = "-";
                data["x"] = flow(x);
                YAML::Node y;
                const auto obs = [&](const char *o, const char *col, const char *unit) {
                    YAML::Node n;
                    n["column"] = col;
                    n["unit"] = unit;
                    y[o] = flow(n);
                };
                obs("traction_N", "F_tractive_N", "N");
                obs("side_force_N", "F_side_N", "N");
                obs("vertical_load_N", "F_load_N", "N");
                // Z_mm is not kept: its zero (the authors' 31.5 mm offset convention) is not the
                // bed surface, so a simulated sinkage could not be compared with it.
                data["y"] = y;
                e["data"] = data;
                list.push_back(e);
                ids.push_back(id);
            }
        }
    }
    if (ids.empty())
        throw std::runtime_error(cmu_directory + ": no plate or wheel tests found");
    root["experiments"] = list;
    save(root, dst / "experiments.yaml",
         "# Written by `grainlink gap import cmu " + cmu_directory +
             "` (docs/gap.md).\n# Source: https://github.com/robomechanics/3d-terramechanics, "
             "MIT licence, (c) 2022 Catherine Pavlov, Carnegie Mellon University.\n");
    loadExperiments(out); // what was written reads back (strictly)
    return ids;
}

namespace {

/// A reader's message, which names data.* keys of experiments.yaml, with the importer's
/// options instead.
std::string withImportOptions(std::string message) {
    // `data.columns: [a, b]` is the option's comma-separated list.
    static const std::regex columns(R"(data\.columns: \[([^\]]*)\])");
    std::smatch m;
    if (std::regex_search(message, m, columns)) {
        std::string list = m[1];
        for (std::size_t at; (at = list.find(", ")) != std::string::npos;)
            list.erase(at + 1, 1);
        message.replace(std::size_t(m.position(0)), std::size_t(m.length(0)), "--columns " + list);
    }
    const std::pair<const char *, const char *> keys[] = {
        {"data.decimal: \",\"", "--decimal ,"},
        {"data.delimiter: ", "--delimiter "},
        {"data.delimiter", "--delimiter"},
        {"data.decimal", "--decimal"},
        {"data.units_row: true", "--units-row"},
        {"data.columns", "--columns"},
        {"data.skip_lines", "--skip-lines"},
        {"start it with data.comment", "start it with the mark of --comment"},
        {"data.comment", "--comment"}};
    for (const auto &[key, option] : keys)
        for (std::size_t at; (at = message.find(key)) != std::string::npos;)
            message.replace(at, std::string(key).size(), option);
    return message;
}

std::string numberText(double v) {
    return config::significant(v, 6);
}

bool isNumberText(const std::string &text) {
    return config::wholeNumber(text).has_value();
}

std::string xOption(const CsvImport &csv) {
    return "--x " + csv.x_column + ":" + csv.x_unit;
}

std::string yOption(const CsvImport &csv, const std::string &observable) {
    const auto &[column, unit] = csv.y.at(observable);
    return "--y " + observable + "=" + column + ":" + unit;
}

std::string zeroOption(const CsvImport &csv) {
    return "--zero " + csv.zero_method +
           (csv.zero_method == "force_threshold"
                ? "=" + numberText(csv.zero_threshold) + ":" + csv.zero_unit
                : std::string());
}

/// The --condition keys as diagnose reads them: a number under an SI name (not "40mm"), and a
/// name the type's test knows; an unknown one is refused where it stands in for the condition
/// the test needs, else returned as a warning (it describes, the simulation does not read it).
std::vector<std::string> checkConditions(const CsvImport &csv, ExperimentType type) {
    const ConditionNames &names = conditionsOf(type);
    // The test's own, under grainlink's name or another (a radius read as its diameter), or
    // describing it.
    std::vector<std::string> known = names.simulated;
    const std::string &needed = names.per_experiment;
    bool needed_given = needed.empty() || csv.conditions.count(needed);
    for (const SizeAlias &a : names.aliases) {
        known.push_back(a.given);
        needed_given = needed_given || (a.name == needed && csv.conditions.count(a.given));
    }
    known.insert(known.end(), describingConditions().begin(), describingConditions().end());
    std::string list;
    for (const auto &c : known)
        list += (list.empty() ? "" : ", ") + c;
    std::vector<std::string> warnings;
    for (const auto &[key, value] : csv.conditions) {
        const std::string option = "--condition " + key + "=" + value;
        const std::string dimension = dimensionOf(key);
        if (dimension != "dimensionless" && !isNumberText(value)) {
            // "40mm": the number it stands for, in the key's SI unit.
            std::string hint;
            char *end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            std::string unit(end);
            unit.erase(0, unit.find_first_not_of(' '));
            try {
                if (end != value.c_str())
                    hint =
                        " (" + numberText(v * unitFactor(unit, dimension)) + " for " + value + ")";
            } catch (const std::invalid_argument &) {
            }
            // "0,02": a decimal comma (--decimal reads the files, not the options).
            if (std::string point = value; point.find(',') != std::string::npos) {
                std::replace(point.begin(), point.end(), ',', '.');
                if (isNumberText(point))
                    hint = " (" + point + " for " + value + ": a decimal point in options)";
            }
            throw std::invalid_argument(option + ": give " + key + " as a number in " +
                                        unitOf(key) + ", the SI unit its name ends in" + hint);
        }
        if (std::find(known.begin(), known.end(), key) != known.end() ||
            (dimension == "dimensionless" && !isNumberText(value)))
            continue; // a text condition names a soil the base may describe
        const std::string why = "'" + key + "' is not a condition of " + csv.type +
                                " (misspelt? its conditions: " + list + ")";
        if (!needed_given)
            throw std::invalid_argument(option + ": " + why + "; its test needs " + needed);
        warnings.push_back(option + ": " + why +
                           ": kept as a description, the simulation does not read it");
    }
    return warnings;
}

/// Everything the options say that no file is needed for: the observables, their units and
/// scales, the zero convention and the conditions. Said by the option, before anything is read
/// or written. Returns the conditions' warnings.
std::vector<std::string> checkOptions(const CsvImport &csv, ExperimentType type, bool scalar) {
    for (const auto &[obs, col] : csv.y)
        if (!isObservableOf(obs, type))
            throw std::invalid_argument(yOption(csv, obs) + ": " + notAnObservable(obs, type));
    const auto checkUnit = [](const std::string &option, const std::string &unit,
                              const std::string &dimension) {
        try {
            unitFactor(unit, dimension);
        } catch (const std::invalid_argument &e) {
            throw std::invalid_argument(option + ": " + e.what());
        }
    };
    if (!scalar)
        checkUnit(xOption(csv), csv.x_unit, dimensionOf(xNameOf(type)));
    for (const auto &[obs, col] : csv.y)
        checkUnit(yOption(csv, obs), col.second, dimensionOf(obs));
    const auto checkScale = [](const std::string &option, double scale) {
        if (scale == 0.0 || !std::isfinite(scale))
            throw std::invalid_argument(option + ": a scale multiplies the column: give a "
                                                 "finite number other than 0");
    };
    if (scalar && csv.x_scale != 1.0)
        throw std::invalid_argument("--x-scale: a " + csv.type + " has no x");
    checkScale("--x-scale " + numberText(csv.x_scale), csv.x_scale);
    for (const auto &[obs, scale] : csv.y_scale) {
        if (!csv.y.count(obs))
            throw std::invalid_argument("--y-scale " + obs + "=" + numberText(scale) + ": no --y " +
                                        obs + "=COLUMN:UNIT to scale");
        checkScale("--y-scale " + obs + "=" + numberText(scale), scale);
    }
    if (!csv.trial_column.empty() && (scalar || csv.scatter))
        throw std::invalid_argument(
            "--trial " + csv.trial_column + ": a " +
            (scalar ? csv.type + "'s values" : std::string("scatter's rows")) +
            " are its trials already");
    if (!csv.zero_method.empty()) {
        if (scalar)
            throw std::invalid_argument(zeroOption(csv) + ": a " + csv.type + " has no x to zero");
        if (csv.zero_method != "as_recorded" && csv.zero_method != "first_sample" &&
            csv.zero_method != "force_threshold")
            throw std::invalid_argument(zeroOption(csv) + ": use as_recorded, first_sample or "
                                                          "force_threshold=VALUE:UNIT");
        // The threshold is a value of the first observable (a plate's force where it gives one).
        if (csv.zero_method == "force_threshold")
            checkUnit(zeroOption(csv), csv.zero_unit, dimensionOf(csv.y.begin()->first));
    }
    return checkConditions(csv, type);
}

/// The rows of `c` holding every value of `filter` (column -> value, as experiments.yaml's
/// data.filter matches them).
DataTable filtered(const DataTable &c, const std::map<std::string, double> &filter) {
    DataTable kept = c;
    kept.rows.clear();
    kept.lines.clear();
    std::vector<std::pair<std::size_t, double>> keys;
    for (const auto &[name, value] : filter) {
        const auto col = c.find(name);
        if (!col)
            throw std::invalid_argument("--filter " + name + "=" + numberText(value) + ": " +
                                        c.missingColumn(name));
        keys.emplace_back(*col, value);
    }
    for (std::size_t r = 0; r < c.rows.size(); ++r) {
        bool selected = true;
        for (const auto &[col, v] : keys)
            selected = selected && !c.missing(r, col) &&
                       std::abs(c.number(r, col) - v) <= 1e-9 * (1 + std::abs(v));
        if (selected) {
            kept.rows.push_back(c.rows[r]);
            kept.lines.push_back(c.lines[r]);
        }
    }
    if (kept.rows.empty() && !keys.empty()) {
        std::string option;
        for (const auto &[name, value] : filter)
            option +=
                (option.empty() ? "--filter " : " --filter ") + name + "=" + numberText(value);
        throw std::invalid_argument(option + ": no row of " + c.file + " holds it");
    }
    return kept;
}

/// A scatter's columns besides those it reads that take a few values, each on several rows:
/// most likely a condition of the test (a wheel's slip angle) merged into one experiment.
std::vector<std::string> varyingColumns(const DataTable &c, const std::vector<std::string> &read,
                                        const std::string &id) {
    std::vector<std::string> warnings;
    // Each column's grouping of the rows (a row's first row of the same value): a column that
    // groups them as one already said does (a side force that follows the slip angle) is not said.
    std::vector<std::vector<std::size_t>> said;
    for (std::size_t col = 0; col < c.header.size(); ++col) {
        if (std::find(read.begin(), read.end(), c.header[col]) != read.end())
            continue;
        std::vector<double> of_row(c.rows.size(), NAN);
        try {
            for (std::size_t r = 0; r < c.rows.size(); ++r)
                if (!c.missing(r, col))
                    of_row[r] = c.number(r, col);
        } catch (const config::ConfigError &) {
            continue; // text: a comment, a label
        }
        std::vector<std::size_t> groups(c.rows.size());
        for (std::size_t r = 0; r < c.rows.size(); ++r)
            groups[r] = std::size_t(
                std::find_if(of_row.begin(), of_row.end(),
                             [&](double v) {
                                 return v == of_row[r] || (std::isnan(v) && std::isnan(of_row[r]));
                             }) -
                of_row.begin());
        if (std::find(said.begin(), said.end(), groups) != said.end())
            continue;
        std::vector<double> values;
        for (double v : of_row)
            if (!std::isnan(v))
                values.push_back(v);
        std::sort(values.begin(), values.end());
        values.erase(std::unique(values.begin(), values.end()), values.end());
        // Three rows a value on average: a run counter or a measured load takes more values.
        if (values.size() < 2 || 3 * values.size() > c.rows.size())
            continue;
        std::string list;
        for (std::size_t i = 0; i < values.size() && i < 5; ++i)
            list += (i ? ", " : "") + numberText(values[i]);
        const std::string name = c.header[col];
        said.push_back(groups);
        warnings.push_back(c.file + ": column '" + name + "' takes " +
                           std::to_string(values.size()) + " values (" + list +
                           (values.size() > 5 ? ", ..." : "") + ") over the " +
                           std::to_string(c.rows.size()) + " rows merged into experiment '" + id +
                           "': if it is a condition of the test (a slip angle, a load), import "
                           "one experiment per value: --filter " +
                           name + "=" + numberText(values[0]) + " --id " + id + "_" +
                           numberText(values[0]) + " with its --condition, and so on");
    }
    return warnings;
}

/// The experiments.yaml node of the import (its copies named in `copies`).
YAML::Node experimentNode(const CsvImport &csv, bool scalar, const std::vector<DataTable> &tables,
                          const std::vector<std::string> &copies) {
    YAML::Node e;
    e["id"] = csv.id;
    e["type"] = csv.type;
    if (!csv.conditions.empty()) {
        YAML::Node cond;
        for (const auto &[k, v] : csv.conditions)
            if (isNumberText(v))
                cond[k] = std::strtod(v.c_str(), nullptr);
            else
                cond[k] = v;
        e["conditions"] = flow(cond);
    }
    YAML::Node data;
    if (scalar) {
        const auto &[obs, col] = *csv.y.begin();
        std::vector<double> values;
        for (const DataTable &c : tables) {
            const std::size_t c_values = column(c, col.first);
            for (std::size_t r = 0; r < c.rows.size(); ++r)
                if (!c.missing(r, c_values))
                    values.push_back(c.number(r, c_values));
        }
        data["values"] = flow(YAML::Node(values));
        data["unit"] = col.second;
    } else {
        data["files"] = flow(YAML::Node(copies));
        if (csv.scatter)
            data["scatter"] = true;
        if (!csv.trial_column.empty())
            data["trial"] = csv.trial_column;
        YAML::Node x;
        x["column"] = csv.x_column;
        x["unit"] = csv.x_unit;
        if (csv.x_scale != 1.0)
            x["scale"] = csv.x_scale;
        data["x"] = flow(x);
        YAML::Node y;
        for (const auto &[obs, col] : csv.y) {
            YAML::Node n;
            n["column"] = col.first;
            n["unit"] = col.second;
            if (const auto s = csv.y_scale.find(obs); s != csv.y_scale.end() && s->second != 1.0)
                n["scale"] = s->second;
            y[obs] = flow(n);
        }
        data["y"] = y;
    }
    e["data"] = data;
    if (!csv.zero_method.empty()) {
        YAML::Node zero;
        zero["method"] = csv.zero_method;
        if (csv.zero_method == "force_threshold") {
            zero["threshold"] = csv.zero_threshold;
            zero["unit"] = csv.zero_unit;
        }
        e["zero"] = flow(zero);
    }
    return e;
}

/// A message of the read-back names experiments.yaml and the data/ copies, which a failed
/// import undoes: said instead with the option or the input file (and its line) it came from.
std::string asImportInput(const std::string &message, const CsvImport &csv, const fs::path &yaml,
                          const std::vector<fs::path> &copies,
                          const std::vector<DataTable> &tables) {
    std::string text = message;
    static const std::regex located(R"(^:\d+: key 'experiments\[\d+\]\.([^']*)': )");
    static const std::regex at_line(R"(^:\d+: )");
    std::smatch m;
    const std::string tail =
        text.rfind(yaml.string(), 0) == 0 ? text.substr(yaml.string().size()) : std::string();
    if (std::regex_search(tail, m, located)) {
        const std::string key = m[1];
        std::string rest = m.suffix();
        std::string option;
        if (key.rfind("conditions.", 0) == 0) {
            const std::string name = key.substr(11);
            const auto given = csv.conditions.find(name);
            option = "--condition " + name +
                     (given == csv.conditions.end() ? std::string() : "=" + given->second);
        } else if (key.rfind("data.y.", 0) == 0) {
            const std::string obs = key.substr(7, key.find('.', 7) - 7);
            option = csv.y.count(obs) ? yOption(csv, obs) : "--y";
        } else if (key.rfind("data.x", 0) == 0) {
            option = xOption(csv);
        } else if (key == "data.values" || key == "data.unit") {
            option = yOption(csv, csv.y.begin()->first);
        } else if (key.rfind("zero", 0) == 0) {
            option = zeroOption(csv);
        }
        if (!option.empty() || key.rfind("data.files", 0) == 0)
            text = (option.empty() ? "" : option + ": ") + rest;
    } else if (std::regex_search(tail, m, at_line)) {
        // Any other message at a line of the written file, which is rolled back and never
        // seen: said without it, by the option where it names one (a zero's threshold).
        text = m.suffix();
        if (text.find("zero.") != std::string::npos)
            text = zeroOption(csv) + ": " +
                   std::regex_replace(text, std::regex("zero\\.threshold"), "its threshold");
    }
    const std::pair<std::string, std::string> keys[] = {
        {"conditions.", "--condition "},
        {"give unit: \"%\"", "give --x " + csv.x_column + ":%"},
        {"add `scale: -1` to a column", "give --x-scale -1 or --y-scale OBS=-1 to a column"},
        {"data.trial: the column that tells them apart (import csv: --trial COLUMN)",
         "--trial COLUMN, the column that tells them apart"}};
    for (const auto &[key, option] : keys)
        for (std::size_t at; (at = text.find(key)) != std::string::npos;)
            text.replace(at, key.size(), option);
    // A copy's line: its two comment lines and header, then the input's rows in order.
    for (std::size_t k = 0; k < copies.size(); ++k)
        for (std::size_t at; (at = text.find(copies[k].string())) != std::string::npos;) {
            std::size_t end = at + copies[k].string().size();
            std::string input = csv.files[k];
            if (end < text.size() && text[end] == ':' && end + 1 < text.size() &&
                std::isdigit(static_cast<unsigned char>(text[end + 1]))) {
                std::size_t digits = end + 1;
                while (digits < text.size() &&
                       std::isdigit(static_cast<unsigned char>(text[digits])))
                    ++digits;
                const long row = std::stol(text.substr(end + 1, digits - end - 1)) - 4;
                if (row >= 0 && std::size_t(row) < tables[k].lines.size())
                    input += ":" + std::to_string(tables[k].lines[std::size_t(row)]);
                end = digits;
            }
            text.replace(at, end - at, input);
        }
    return text;
}

} // namespace

std::vector<std::string> importCsv(const CsvImport &csv, const std::string &out) {
    const fs::path dst(out);
    const ExperimentType type = parseType(csv.type);
    if (csv.id.empty() || csv.id[0] == '.' || csv.id.find_first_of(" /\\\t\n") != std::string::npos)
        throw std::invalid_argument("--id '" + csv.id +
                                    "': an id is one word without spaces or "
                                    "slashes");
    const bool scalar = std::string(xNameOf(type)).empty();
    if (scalar != csv.x_column.empty())
        throw std::invalid_argument(scalar ? "--x: a " + csv.type +
                                                 " is one value a row (its --y column): give no --x"
                                           : "--x COLUMN:UNIT: a " + csv.type + " needs its x");
    if (csv.y.empty() || (scalar && csv.y.size() != 1))
        throw std::invalid_argument(scalar ? "--y: give one column of values"
                                           : "--y: name at least one observable");

    if (csv.files.empty())
        throw std::invalid_argument("give the CSV file (or one file per repeat)");
    // Options before anything is read or written: an error names the option, not a file the
    // import would have written and undone.
    std::vector<std::string> warnings = checkOptions(csv, type, scalar);

    // Read and checked before anything is written: an error names the user's file and line.
    TableFormat format;
    format.delimitedBy(csv.delimiter);
    format.decimal = csv.decimal.empty() ? '.' : csv.decimal[0];
    format.comment = csv.comment;
    format.columns = csv.columns;
    format.units_row = csv.units_row;
    format.skip_lines = csv.skip_lines;
    std::vector<std::string> columns;
    if (!csv.x_column.empty())
        columns.push_back(csv.x_column);
    for (const auto &[obs, col] : csv.y)
        columns.push_back(col.first);
    // What each copy keeps: the columns read, and the trial column (a run's name or number).
    std::vector<std::string> copied = columns;
    if (!csv.trial_column.empty())
        copied.push_back(csv.trial_column);
    std::vector<DataTable> tables;
    for (const std::string &file : csv.files) {
        try {
            tables.push_back(filtered(readDataTable(file, format), csv.filter));
            const DataTable &c = tables.back();
            if (!csv.trial_column.empty())
                column(c, csv.trial_column);
            // The file's own units row against the options' units.
            if (!scalar)
                if (const std::string why = unitsRowDisagreement(
                        c, column(c, csv.x_column), csv.x_unit, dimensionOf(xNameOf(type)));
                    !why.empty())
                    throw std::invalid_argument(xOption(csv) + ": " + why);
            for (const auto &[obs, col] : csv.y)
                if (const std::string why =
                        unitsRowDisagreement(c, column(c, col.first), col.second, dimensionOf(obs));
                    !why.empty())
                    throw std::invalid_argument(yOption(csv, obs) + ": " + why);
            for (const std::string &name : columns) {
                const std::size_t col = column(c, name);
                std::vector<int> missing;
                for (std::size_t r = 0; r < c.rows.size(); ++r)
                    if (!c.missing(r, col))
                        c.number(r, col);
                    else
                        missing.push_back(c.lines[r]);
                // A curve's gaps stay in its copy, and the diagnosis says them as it reads
                // it; a scalar's values are written inline, so they are said here.
                if (scalar && !missing.empty())
                    warnings.push_back(file + ": " + std::to_string(missing.size()) + " of " +
                                       std::to_string(c.rows.size()) + " rows miss a value in '" +
                                       name + "' (empty or NaN); those are left out (lines " +
                                       lineList(missing) + ")");
            }
        } catch (const config::ConfigError &e) {
            throw config::ConfigError(withImportOptions(e.what()));
        }
        if (csv.scatter) {
            std::vector<std::string> read = columns;
            for (const auto &[name, value] : csv.filter)
                read.push_back(name);
            for (std::string &w : varyingColumns(tables.back(), read, csv.id))
                warnings.push_back(std::move(w));
        }
    }

    const fs::path yaml = dst / "experiments.yaml";
    YAML::Node root = loadOrNew(yaml, folderName(out));
    for (const auto &e : root["experiments"])
        if (e["id"].as<std::string>() == csv.id)
            throw std::invalid_argument("experiment id '" + csv.id + "' is already in " +
                                        yaml.string());
    // The copies: data/ID.csv, or data/ID_1.csv ... for repeats.
    std::vector<std::string> copies;
    std::vector<fs::path> copy_paths;
    for (std::size_t k = 0; !scalar && k < tables.size(); ++k) {
        copies.push_back("data/" + csv.id +
                         (tables.size() > 1 ? "_" + std::to_string(k + 1) : std::string()) +
                         ".csv");
        copy_paths.push_back(dst / copies.back());
        if (fs::exists(copy_paths.back()))
            throw std::invalid_argument(copy_paths.back().string() +
                                        " exists already: give another --id");
    }
    const YAML::Node e = experimentNode(csv, scalar, tables, copies);
    std::string rows; // the copy's header says which rows it holds
    for (const auto &[name, value] : csv.filter)
        rows += (rows.empty() ? ", the rows with " : " and ") + name + " = " + numberText(value);

    // Written, read back strictly, and undone if it does not read: a failed import leaves the
    // folder as it was.
    const bool existed = fs::exists(yaml), had_out = fs::exists(dst),
               had_data = fs::exists(dst / "data");
    std::string before;
    if (existed) {
        std::ifstream in(yaml);
        before.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    fs::create_directories(dst / "data");
    try {
        for (std::size_t k = 0; k < copies.size(); ++k)
            writeColumns(tables[k], copied, csv.files[k], copy_paths[k],
                         "imported by grainlink gap import csv" + rows);
        root["experiments"].push_back(e);
        save(root, yaml, "# Measurements for grainlink gap (docs/gap.md).\n");
        loadExperiments(out);
    } catch (const std::exception &error) {
        for (const fs::path &copy : copy_paths)
            fs::remove(copy);
        if (existed) {
            std::ofstream(yaml.string() + ".tmp") << before;
            fs::rename(yaml.string() + ".tmp", yaml);
        } else {
            fs::remove(yaml);
        }
        if (!had_data)
            fs::remove(dst / "data");
        if (!had_out)
            fs::remove(dst);
        throw std::invalid_argument(asImportInput(error.what(), csv, yaml, copy_paths, tables));
    }
    return warnings;
}

} // namespace grainlink::gap
