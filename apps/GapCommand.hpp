#pragma once
// `grainlink gap`: the sim-to-real diagnosis (docs/gap.md) — import measurements, diagnose
// them against a base model, make twins whose cause is known, and the blind self-test.
#include "ExecutorFlags.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::apps {

class GapCommand {
public:
    explicit GapCommand(CLI::App &app);
    bool parsed() const { return command_->parsed(); }
    int run() const;

private:
    int diagnose() const;
    int twin() const;
    int selftest() const;
    int importCmu() const;
    int importCsv() const;

    CLI::App *command_, *diagnose_, *twin_, *selftest_, *import_, *import_cmu_, *import_csv_;
    // shared
    std::string model_, out_, sims_, effects_file_;
    ExecutorFlags executor_;
    // diagnose
    std::string measurements_;
    std::vector<std::string> held_out_, only_;
    bool dry_run_ = false;
    // twin
    std::string design_, effect_, key_;
    std::optional<double> strength_;
    bool random_ = false, null_ = false;
    unsigned seed_ = 1;
    double noise_ = 0.01, level_noise_ = 0.02;
    bool own_beds_ = false;
    // selftest
    std::string scale_ = "ci", plan_;
    // import
    std::string source_, sinkage_ = "synced", csv_id_, csv_type_, csv_x_, csv_zero_, csv_trial_;
    std::vector<std::string> csv_files_, csv_y_, csv_conditions_, csv_columns_, csv_y_scale_,
        csv_filter_;
    double csv_x_scale_ = 1.0;
    int csv_skip_lines_ = 0;
    bool csv_scatter_ = false, csv_units_row_ = false, no_wheels_ = false, no_plates_ = false;
    std::string csv_delimiter_ = ",", csv_decimal_ = ".", csv_comment_ = "#";
};

} // namespace grainlink::apps
