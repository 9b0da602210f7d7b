#include "grainlink/study/Kind.hpp"

#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/Bevameter.hpp"
#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/lab/Repose.hpp"
#include "grainlink/lab/ShearAnnulus.hpp"

#include <stdexcept>

namespace grainlink::study {

Kind standardKind(const std::string &kind, const std::string &test) {
    if (kind == "dem") {
        if (!test.empty())
            throw std::invalid_argument("kind 'dem' takes no test (got '" + test + "')");
        return {"dem",
                {"dem"},
                "summary.json",
                "simulation.threads",
                "deposition.seed",
                [](const config::ConfigNode &root) { dem::parseScenario(root); }};
    }
    if (kind == "run") {
        if (!test.empty())
            throw std::invalid_argument("kind 'run' takes no test (got '" + test + "')");
        // The coupled rig's machine-readable summary comes with its own issue; the name is
        // fixed here so a study of coupled runs needs no change when it arrives.
        return {
            "run", {"run"}, "rig_summary.json", "soil.simulation.threads", "soil.deposition.seed",
            {}};
    }
    if (kind == "lab") {
        std::function<void(const config::ConfigNode &)> parse;
        if (test == "bevameter")
            parse = [](const config::ConfigNode &root) { lab::parseBevameter(root); };
        else if (test == "repose")
            parse = [](const config::ConfigNode &root) { lab::parseRepose(root); };
        else if (test == "direct_shear")
            parse = [](const config::ConfigNode &root) { lab::parseDirectShear(root); };
        else if (test == "bevameter_shear")
            parse = [](const config::ConfigNode &root) { lab::parseShearAnnulus(root); };
        else
            throw std::invalid_argument("lab test '" + test +
                                        "' is not one of: bevameter, repose, direct_shear, "
                                        "bevameter_shear");
        return {"lab " + test,          {"lab", test}, "summary.json", "soil.simulation.threads",
                "soil.deposition.seed", parse};
    }
    throw std::invalid_argument("kind '" + kind + "' is not one of: dem, run, lab");
}

} // namespace grainlink::study
