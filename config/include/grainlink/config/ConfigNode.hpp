#pragma once
// Strict reading of a YAML file: every error names the file, the key path and the line, and a
// mapping whose keys were not all read is an error (unknown key, or a unit the key does not take).
#include <Eigen/Core>

#include <yaml-cpp/yaml.h>

#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainlink::config {

using Vec3 = Eigen::Vector3d;

class ConfigError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Something about a key worth saying that is not an error (an old spelling, a box too narrow
/// for its grains): where it was written kept apart from what is said, so that a caller can
/// say it at another file's line (the gap's base model for the scenario made from it).
struct KeyWarning {
    std::string file;
    int line = 0;
    std::string key; ///< its path, e.g. direct_shear.width_m
    std::string message;
    /// `file:line: warning: 'key': message`
    std::string text() const;
};

class ConfigNode {
public:
    /// Loads a file; a YAML syntax error is reported with its line.
    static ConfigNode loadFile(const std::string &path);
    static ConfigNode loadString(const std::string &text, const std::string &name);

    const std::string &path() const { return path_; }
    const std::string &file() const { return *file_; }
    int line() const { return node_.Mark().line + 1; }
    bool isMap() const { return node_.IsMap(); }
    bool isSequence() const { return node_.IsSequence(); }
    bool isScalar() const { return node_.IsScalar(); }

    bool has(const std::string &key) const;
    ConfigNode operator[](const std::string &key) const;              ///< required
    std::optional<ConfigNode> optional(const std::string &key) const; ///< may be absent
    std::vector<ConfigNode> items() const;                            ///< a sequence
    std::vector<std::string> keys() const; ///< a mapping's keys in file order (none are marked read)
    bool isNumber() const;                 ///< a scalar that reads as a finite number

    double number() const;
    // Range rules: each fails with the file, the key and the line, naming the range.
    double positive() const;                    ///< > 0
    double nonNegative() const;                 ///< >= 0
    double number(double lo, double hi) const;  ///< in [lo, hi]
    long long integer() const;
    /// A whole number in [lo, hi]: counts and sizes are bounded, so that a wrapped negative or
    /// an absurd value stops here instead of exhausting memory or a library later.
    long long integer(long long lo, long long hi) const;
    std::vector<double> positives() const;      ///< a non-empty list, every item > 0
    bool boolean() const;
    std::string text() const;
    /// One of `choices`; otherwise an error listing them.
    std::string choice(const std::vector<std::string> &choices) const;
    Vec3 vec3() const;
    std::vector<double> numbers() const;
    /// The value as YAML, unchecked (a study copies values into scenarios).
    const YAML::Node &yaml() const { return node_; }

    double number(const std::string &key, double fallback) const;
    long long integer(const std::string &key, long long lo, long long hi, long long fallback) const;
    std::string text(const std::string &key, const std::string &fallback) const;
    bool boolean(const std::string &key, bool fallback) const;

    /// Throws on the first key of this mapping that was never read, suggesting a near match.
    void finish() const;
    [[noreturn]] void fail(const std::string &message) const;
    /// This key's file, line and path with `message`: what `fail` says, as a warning.
    KeyWarning warning(const std::string &message) const;

private:
    /// Throws when `key` appears twice in this mapping, naming both lines.
    void refuseDuplicate(const std::string &key) const;
    /// A mapping key's text; throws with the file and line unless it is a scalar.
    std::string keyText(const YAML::Node &key) const;
    ConfigNode(YAML::Node node, std::shared_ptr<const std::string> file, std::string path);
    YAML::Node node_;
    std::shared_ptr<const std::string> file_;
    std::string path_;
    std::shared_ptr<std::set<std::string>> used_;
};

/// Whether `given` reads as a misspelling of `known`: the same but for case (X for x), or one
/// letter off in a word of four or more (repeat for repeats), two in one of eight or more.
bool misspelling(const std::string &given, const std::string &known);

/// A dotted key's step as a list index ("3" in `walls.3.upper_m`): digits only, and short enough
/// for any list (at most 9 digits); anything else, an overflowing number included, is none.
std::optional<std::size_t> listIndex(const std::string &step);

} // namespace grainlink::config
