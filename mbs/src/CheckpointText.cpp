#include "CheckpointText.hpp"

#include "grainlink/mbs/MultibodyModel.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace grainlink::mbs {

std::vector<double> checkpointNumbers(std::istream &in, const std::string &path, int number,
                                      const std::string &kind, const std::string &tag,
                                      const std::string &what) {
    const std::string where = path + ":" + std::to_string(number) + ": ";
    std::string line;
    if (!std::getline(in, line))
        throw ModelError(where + "missing the line '" + tag + " ...' (" + what + "): truncated " +
                         kind + " checkpoint");
    std::istringstream words(line);
    std::string word;
    if (!(words >> word) || word != tag)
        throw ModelError(where + "expected '" + tag + " ...' (" + what + "), got '" +
                         line.substr(0, 40) + "'" +
                         (number == 1 ? ": not a " + kind + " checkpoint" : ""));
    std::vector<double> values;
    while (words >> word) {
        char *end = nullptr;
        const double value = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0' || !std::isfinite(value))
            throw ModelError(where + "'" + word.substr(0, 40) + "' in " + what +
                             " is not a finite number");
        values.push_back(value);
    }
    return values;
}

std::vector<double> checkpointNumbers(std::istream &in, const std::string &path, int number,
                                      const std::string &kind, const std::string &tag,
                                      std::size_t count, const std::string &what) {
    auto values = checkpointNumbers(in, path, number, kind, tag, what);
    if (values.size() != count)
        throw ModelError(path + ":" + std::to_string(number) + ": " +
                         std::to_string(values.size()) + " values of " + what +
                         ", this model has " + std::to_string(count) +
                         " (a checkpoint of another model?)");
    return values;
}

} // namespace grainlink::mbs
