#include "grainlink/gap/Importers.hpp"

#include "grainlink/gap/Experiments.hpp"

#include "DataTable.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
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
    const std::pair<const char *, const char *> keys[] = {{"data.decimal: \",\"", "--decimal ,"},
                                                          {"data.delimiter: ", "--delimiter "},
                                                          {"data.delimiter", "--delimiter"},
                                                          {"data.decimal", "--decimal"},
                                                          {"data.units_row: true", "--units-row"},
                                                          {"data.columns: ", "--columns "},
                                                          {"data.columns", "--columns"},
                                                          {"give data.skip_lines (the lines before "
                                                           "the header) or start it with "
                                                           "data.comment",
                                                           "delete it, or start it with the mark "
                                                           "of --comment"}};
    for (const auto &[key, option] : keys)
        for (std::size_t at; (at = message.find(key)) != std::string::npos;)
            message.replace(at, std::string(key).size(), option);
    return message;
}

} // namespace

void importCsv(const CsvImport &csv, const std::string &out) {
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
    // Units before anything is read or written: an error names the option, not a file the
    // import would have written and undone.
    const auto checkUnit = [](const std::string &option, const std::string &unit,
                              const std::string &si_name) {
        try {
            unitFactor(unit, dimensionOf(si_name));
        } catch (const std::invalid_argument &e) {
            throw std::invalid_argument(option + ": " + e.what());
        }
    };
    if (!scalar) {
        checkUnit("--x " + csv.x_column + ":" + csv.x_unit, csv.x_unit, xNameOf(type));
        for (const auto &[obs, col] : csv.y)
            checkUnit("--y " + obs + "=" + col.first + ":" + col.second, col.second, obs);
    }

    // Read and checked before anything is written: an error names the user's file and line.
    TableFormat format;
    format.delimitedBy(csv.delimiter);
    format.decimal = csv.decimal.empty() ? '.' : csv.decimal[0];
    format.comment = csv.comment;
    format.columns = csv.columns;
    format.units_row = csv.units_row;
    std::vector<std::string> columns;
    if (!csv.x_column.empty())
        columns.push_back(csv.x_column);
    for (const auto &[obs, col] : csv.y)
        columns.push_back(col.first);
    std::vector<DataTable> tables;
    for (const std::string &file : csv.files) {
        try {
            tables.push_back(readDataTable(file, format));
            const DataTable &c = tables.back();
            for (const std::string &name : columns) {
                const std::size_t col = column(c, name);
                for (std::size_t r = 0; r < c.rows.size(); ++r)
                    if (!c.missing(r, col))
                        c.number(r, col);
            }
        } catch (const config::ConfigError &e) {
            throw config::ConfigError(withImportOptions(e.what()));
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
    for (std::size_t k = 0; !scalar && k < tables.size(); ++k) {
        copies.push_back("data/" + csv.id +
                         (tables.size() > 1 ? "_" + std::to_string(k + 1) : std::string()) +
                         ".csv");
        if (fs::exists(dst / copies.back()))
            throw std::invalid_argument((dst / copies.back()).string() +
                                        " exists already: give another --id");
    }

    YAML::Node e;
    e["id"] = csv.id;
    e["type"] = csv.type;
    if (!csv.conditions.empty()) {
        YAML::Node cond;
        for (const auto &[k, v] : csv.conditions) {
            char *end = nullptr;
            const double d = std::strtod(v.c_str(), &end);
            if (!v.empty() && end == v.c_str() + v.size())
                cond[k] = d;
            else
                cond[k] = v;
        }
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
        YAML::Node x;
        x["column"] = csv.x_column;
        x["unit"] = csv.x_unit;
        data["x"] = flow(x);
        YAML::Node y;
        for (const auto &[obs, col] : csv.y) {
            YAML::Node n;
            n["column"] = col.first;
            n["unit"] = col.second;
            y[obs] = flow(n);
        }
        data["y"] = y;
    }
    e["data"] = data;

    // Written, read back strictly, and undone if it does not read: a failed import leaves the
    // folder as it was.
    const bool existed = fs::exists(yaml);
    std::string before;
    if (existed) {
        std::ifstream in(yaml);
        before.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    fs::create_directories(dst / "data");
    try {
        for (std::size_t k = 0; k < copies.size(); ++k)
            writeColumns(tables[k], columns, csv.files[k], dst / copies[k],
                         "imported by grainlink gap import csv");
        root["experiments"].push_back(e);
        save(root, yaml, "# Measurements for grainlink gap (docs/gap.md).\n");
        loadExperiments(out);
    } catch (...) {
        for (const std::string &copy : copies)
            fs::remove(dst / copy);
        if (existed) {
            std::ofstream(yaml.string() + ".tmp") << before;
            fs::rename(yaml.string() + ".tmp", yaml);
        } else {
            fs::remove(yaml);
        }
        throw;
    }
}

} // namespace grainlink::gap
