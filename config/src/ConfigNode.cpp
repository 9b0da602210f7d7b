#include "grainlink/config/ConfigNode.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

namespace grainlink::config {

namespace {
/// "time_step_ms" and "time_step_s" share the stem "time_step": a wrong unit, not a typo.
std::string stem(const std::string &key) {
    const auto cut = key.rfind('_');
    return cut == std::string::npos ? key : key.substr(0, cut);
}

/// Whether `a` and `b` are one quantity in two units: the same stem, and each ending in a
/// unit (y_sigam beside y_relative is a typo, not a unit).
bool otherUnit(const std::string &a, const std::string &b) {
    static const std::set<std::string> units = {
        // lower case: youngs_modulus_pa too
        "s",  "ms",  "us",  "min", "h", "m",  "mm", "cm",  "um",     "km",
        "pa", "kpa", "mpa", "gpa", "n", "kn", "mn", "deg", "rad",    "kg",
        "g",  "m2",  "m3",  "s2",  "j", "w",  "hz", "k",   "percent"};
    const auto suffix = [](const std::string &k) {
        const auto cut = k.rfind('_');
        std::string s = cut == std::string::npos ? std::string() : k.substr(cut + 1);
        for (char &c : s)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        return s;
    };
    return a != b && stem(a) == stem(b) && units.count(suffix(a)) && units.count(suffix(b));
}
} // namespace

bool misspelling(const std::string &a, const std::string &b) {
    std::string x = a, y = b;
    for (char &c : x)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    for (char &c : y)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    if (x == y)
        return a != b;
    // Levenshtein distance, one row at a time.
    std::vector<std::size_t> row(y.size() + 1);
    for (std::size_t j = 0; j <= y.size(); ++j)
        row[j] = j;
    for (std::size_t i = 1; i <= x.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= y.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (x[i - 1] != y[j - 1])});
            diagonal = up;
        }
    }
    const std::size_t d = row[y.size()], n = std::min(x.size(), y.size());
    return (n >= 4 && d <= 1) || (n >= 8 && d <= 2);
}

ConfigNode::ConfigNode(YAML::Node node, std::shared_ptr<const std::string> file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)),
      used_(std::make_shared<std::set<std::string>>()) {}

ConfigNode ConfigNode::loadFile(const std::string &path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw ConfigError(path + ": is a folder, not a YAML file");
    try {
        YAML::Node root = YAML::LoadFile(path);
        if (!root || root.IsNull())
            throw ConfigError(path + ":1: the file is empty");
        return ConfigNode(std::move(root), std::make_shared<std::string>(path), "");
    } catch (const YAML::BadFile &) {
        throw ConfigError(path + ": cannot open file");
    } catch (const YAML::ParserException &e) {
        throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) +
                          ": YAML syntax error: " + e.msg);
    }
}

ConfigNode ConfigNode::loadString(const std::string &text, const std::string &name) {
    try {
        return ConfigNode(YAML::Load(text), std::make_shared<std::string>(name), "");
    } catch (const YAML::ParserException &e) {
        throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) +
                          ": YAML syntax error: " + e.msg);
    }
}

std::string KeyWarning::text() const {
    return file + ":" + std::to_string(line) + ": warning: '" + key + "': " + message;
}

KeyWarning ConfigNode::warning(const std::string &message) const {
    return {*file_, line(), path_, message};
}

void ConfigNode::fail(const std::string &message) const {
    std::ostringstream out;
    out << *file_ << ":" << line() << ": ";
    if (!path_.empty())
        out << "key '" << path_ << "': ";
    out << message;
    throw ConfigError(out.str());
}

bool ConfigNode::has(const std::string &key) const {
    return node_.IsMap() && node_[key];
}

void ConfigNode::refuseDuplicate(const std::string &key) const {
    // yaml-cpp keeps every pair of a mapping and looks up the first: a second one would be
    // silently ignored.
    int first_line = 0;
    for (const auto &entry : node_) {
        if (!entry.first.IsScalar() || entry.first.Scalar() != key)
            continue;
        if (first_line == 0) {
            first_line = entry.first.Mark().line + 1;
            continue;
        }
        std::ostringstream out;
        out << *file_ << ":" << entry.first.Mark().line + 1 << ": key '"
            << (path_.empty() ? key : path_ + "." + key) << "' given twice (first at line "
            << first_line << ")";
        throw ConfigError(out.str());
    }
}

ConfigNode ConfigNode::operator[](const std::string &key) const {
    if (!node_.IsMap())
        fail("expected a mapping with key '" + key + "'");
    refuseDuplicate(key);
    used_->insert(key);
    const YAML::Node child = node_[key];
    const std::string child_path = path_.empty() ? key : path_ + "." + key;
    if (!child || child.IsNull()) {
        // A key with the same stem but another unit suffix is a wrong unit, not a missing key.
        for (const auto &entry : node_) {
            const std::string other = keyText(entry.first);
            if (otherUnit(other, key)) {
                std::ostringstream out;
                out << *file_ << ":" << entry.first.Mark().line + 1 << ": unknown key '"
                    << (path_.empty() ? other : path_ + "." + other)
                    << "' (wrong unit? this key is '" << key << "')";
                throw ConfigError(out.str());
            }
        }
        std::ostringstream out;
        out << *file_ << ":" << line() << ": missing key '" << child_path << "'";
        // Said as missing still (the other may be a key of its own), with the likely typo.
        for (const auto &entry : node_)
            if (const std::string other = keyText(entry.first); misspelling(other, key)) {
                out << " ('" << other << "' at line " << entry.first.Mark().line + 1
                    << " misspelt?)";
                break;
            }
        throw ConfigError(out.str());
    }
    return ConfigNode(child, file_, child_path);
}

std::string ConfigNode::keyText(const YAML::Node &key) const {
    // YAML allows a list or a mapping as a key ({[1, 2]: x}); no grainlink key is one.
    if (!key.IsScalar()) {
        std::ostringstream out;
        out << *file_ << ":" << key.Mark().line + 1 << ": a key of '"
            << (path_.empty() ? std::string("the file") : path_)
            << "' is a list or a mapping; keys are plain words";
        throw ConfigError(out.str());
    }
    return key.Scalar();
}

std::vector<std::string> ConfigNode::keys() const {
    if (!node_.IsMap())
        fail("expected a mapping");
    std::vector<std::string> out;
    for (const auto &entry : node_)
        out.push_back(keyText(entry.first));
    return out;
}

bool ConfigNode::isNumber() const {
    if (!node_.IsScalar())
        return false;
    const std::string s = node_.Scalar();
    char *end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    return !s.empty() && end == s.c_str() + s.size() && std::isfinite(v);
}

std::optional<ConfigNode> ConfigNode::optional(const std::string &key) const {
    if (!node_.IsMap())
        fail("expected a mapping");
    refuseDuplicate(key);
    used_->insert(key);
    if (!node_[key] || node_[key].IsNull())
        return std::nullopt;
    return (*this)[key];
}

std::vector<ConfigNode> ConfigNode::items() const {
    if (!node_.IsSequence())
        fail("expected a list");
    std::vector<ConfigNode> out;
    for (std::size_t k = 0; k < node_.size(); ++k)
        out.push_back(ConfigNode(node_[k], file_, path_ + "[" + std::to_string(k) + "]"));
    return out;
}

double ConfigNode::number() const {
    if (!node_.IsScalar())
        fail("expected a number");
    const std::string s = node_.Scalar();
    std::size_t used = 0;
    try {
        const double v = std::stod(s, &used);
        if (used != s.size() || !std::isfinite(v))
            throw std::invalid_argument(s);
        return v;
    } catch (const std::exception &) {
        // A number with its unit written after it ("20 kPa"): the key's name carries the unit.
        const bool unit_after =
            used > 0 && used < s.size() && s.find_first_not_of(' ', used) != std::string::npos &&
            std::isalpha(static_cast<unsigned char>(s[s.find_first_not_of(' ', used)]));
        fail("expected a number, got '" + s + "'" +
             (unit_after ? ": give the number alone, in the unit its key's name ends with "
                           "(_Pa, _m, _N, _s, ...)"
                         : ""));
    }
}

double ConfigNode::positive() const {
    const double v = number();
    if (!(v > 0.0))
        fail("must be > 0, got " + node_.Scalar());
    return v;
}

double ConfigNode::nonNegative() const {
    const double v = number();
    if (!(v >= 0.0))
        fail("must be >= 0, got " + node_.Scalar());
    return v;
}

double ConfigNode::number(double lo, double hi) const {
    const double v = number();
    if (!(v >= lo && v <= hi)) {
        std::ostringstream range;
        range << "must be in [" << lo << ", " << hi << "], got " << node_.Scalar();
        fail(range.str());
    }
    return v;
}

long long ConfigNode::integer() const {
    const double v = number();
    if (v != std::floor(v))
        fail("expected a whole number, got " + node_.Scalar());
    // Beyond 2^53 a double no longer holds every whole number, and the cast may overflow.
    if (std::abs(v) > 9.0e15)
        fail("whole number out of range, got " + node_.Scalar());
    return static_cast<long long>(v);
}

long long ConfigNode::integer(long long lo, long long hi) const {
    const long long v = integer();
    if (v < lo || v > hi)
        fail("must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
             "], got " + node_.Scalar());
    return v;
}

std::vector<double> ConfigNode::positives() const {
    std::vector<double> out;
    for (const ConfigNode &item : items())
        out.push_back(item.positive());
    if (out.empty())
        fail("give at least one value");
    return out;
}

bool ConfigNode::boolean() const {
    const std::string s = text();
    if (s == "true" || s == "yes" || s == "on")
        return true;
    if (s == "false" || s == "no" || s == "off")
        return false;
    fail("expected true or false, got '" + s + "'");
}

std::string ConfigNode::text() const {
    if (!node_.IsScalar())
        fail("expected a single value");
    return node_.Scalar();
}

std::string ConfigNode::choice(const std::vector<std::string> &choices) const {
    const std::string s = text();
    for (const std::string &c : choices)
        if (c == s)
            return s;
    std::string list;
    for (const std::string &c : choices)
        list += (list.empty() ? "" : ", ") + c;
    fail("'" + s + "' is not one of: " + list);
}

Vec3 ConfigNode::vec3() const {
    const std::vector<double> v = numbers();
    if (v.size() != 3)
        fail("expected a list of 3 numbers, got " + std::to_string(v.size()));
    return Vec3(v[0], v[1], v[2]);
}

std::vector<double> ConfigNode::numbers() const {
    std::vector<double> out;
    for (const ConfigNode &item : items())
        out.push_back(item.number());
    return out;
}

double ConfigNode::number(const std::string &key, double fallback) const {
    const auto n = optional(key);
    return n ? n->number() : fallback;
}

long long ConfigNode::integer(const std::string &key, long long lo, long long hi,
                              long long fallback) const {
    const auto n = optional(key);
    return n ? n->integer(lo, hi) : fallback;
}

std::string ConfigNode::text(const std::string &key, const std::string &fallback) const {
    const auto n = optional(key);
    return n ? n->text() : fallback;
}

bool ConfigNode::boolean(const std::string &key, bool fallback) const {
    const auto n = optional(key);
    return n ? n->boolean() : fallback;
}

void ConfigNode::finish() const {
    if (!node_.IsMap())
        return;
    for (const auto &entry : node_) {
        const std::string key = keyText(entry.first);
        if (used_->count(key))
            continue;
        std::string hint;
        for (const std::string &known : *used_)
            if (otherUnit(known, key))
                hint = " (wrong unit? this key is '" + known + "')";
            else if (hint.empty() && misspelling(key, known))
                hint = " (misspelt? a key read here is '" + known + "')";
        std::ostringstream out;
        out << *file_ << ":" << entry.first.Mark().line + 1 << ": unknown key '"
            << (path_.empty() ? key : path_ + "." + key) << "'" << hint;
        throw ConfigError(out.str());
    }
}

std::optional<std::size_t> listIndex(const std::string &step) {
    if (step.empty() || step.size() > 9 ||
        step.find_first_not_of("0123456789") != std::string::npos)
        return std::nullopt;
    return std::size_t(std::stoul(step));
}

} // namespace grainlink::config
