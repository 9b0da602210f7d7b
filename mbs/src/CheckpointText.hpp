#pragma once
// The multibody side's text checkpoints (a model's rig.txt / model.txt, the wheel test's
// wheel_test.txt): one line per quantity, a tag and then its numbers with round-trip precision,
// read back strictly. Internal to mbs/.
#include <istream>
#include <string>
#include <vector>

namespace grainlink::mbs {

/// Reads line `number` of the `kind` checkpoint `path` ("multibody", "wheel test"): `tag`, then
/// finite numbers. Throws ModelError naming the file, the line and `what` the line holds when the
/// line is missing (a truncated checkpoint), has another tag or holds a word that is not a finite
/// number.
std::vector<double> checkpointNumbers(std::istream &in, const std::string &path, int number,
                                      const std::string &kind, const std::string &tag,
                                      const std::string &what);

/// The same for a line of exactly `count` numbers ("... values of `what`, this model has ...").
std::vector<double> checkpointNumbers(std::istream &in, const std::string &path, int number,
                                      const std::string &kind, const std::string &tag,
                                      std::size_t count, const std::string &what);

} // namespace grainlink::mbs
