// Fuzz target: the plain CSV importer (`grainlink gap import csv`, docs/gap.md) on one plate
// sinkage file, and the measurements folder it writes read back.
#include "FuzzTarget.hpp"
#include "grainlink/gap/Experiments.hpp"
#include "grainlink/gap/Importers.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string folder = fz::freshFolder();
    gap::CsvImport csv;
    csv.files = {fz::writeFile(folder, "plate.csv",
                               std::string_view(reinterpret_cast<const char *>(data), size))};
    csv.id = "plate";
    csv.type = "plate_sinkage";
    csv.x_column = "z_mm";
    csv.x_unit = "mm";
    csv.y["pressure_Pa"] = {"p_kPa", "kPa"};
    csv.conditions["plate_diameter_m"] = "0.06";
    fz::expectClearError(folder, [&] {
        gap::importCsv(csv, folder + "/measurements");
        gap::loadExperiments(folder + "/measurements");
    });
    return 0;
}
