// `grainlink params SOIL.yaml [--out FILE]`: the seed's parameter estimation (docs/lab.md).
#include "LabCommands.hpp"

#include "grainlink/lab/ParameterEstimation.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace grainlink::apps {

namespace fs = std::filesystem;

int runParams(const ParamsOptions &options) {
    if (options.friction_angle_deg) {
        if (!options.input_path.empty())
            throw std::invalid_argument("give either a soil description file or "
                                        "--friction-angle, not both");
        return runTableInversion(options);
    }
    if (options.repose_angle_deg)
        throw std::invalid_argument("--repose-angle needs --friction-angle");
    if (options.input_path.empty())
        throw std::invalid_argument("give a soil description file (docs/lab.md) or "
                                    "--friction-angle PSI");
    const auto description = lab::loadSoilTestDescription(options.input_path);
    const auto matrix = lab::estimateParameters(description);
    const fs::path out =
        options.output_path.empty()
            ? fs::path("out/params") / (fs::path(options.input_path).stem().string() + ".yaml")
            : fs::path(options.output_path);
    const std::string ext = out.extension().string();
    if (ext != ".yaml" && ext != ".yml" && ext != ".csv")
        throw std::invalid_argument("--out " + out.string() +
                                    ": the file name must end in .yaml, .yml or .csv");
    if (out.has_parent_path())
        fs::create_directories(out.parent_path());
    std::ofstream file(out);
    if (!file)
        throw std::runtime_error("cannot write " + out.string());
    file << (ext == ".csv" ? lab::formatCsv(matrix) : lab::formatYaml(matrix));

    std::printf("%s\n", lab::formatTable(matrix).c_str());
    std::printf("Ready to paste into a scenario (docs/scenario.md):\n\n%s\n",
                lab::soilBlock(matrix).c_str());
    std::printf("written: %s\n", out.c_str());
    return 0;
}

} // namespace grainlink::apps
