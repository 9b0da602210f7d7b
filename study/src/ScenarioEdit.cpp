#include "grainlink/study/ScenarioEdit.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace grainlink::study {

namespace {

std::string keysOf(const YAML::Node &map) {
    std::string list;
    for (const auto &entry : map)
        if (entry.first.IsScalar()) // the strict reader refuses other keys, naming the line
            list += (list.empty() ? "" : ", ") + entry.first.Scalar();
    return list;
}

/// The child `step` of `node`, or an undefined node; `what` says why when there is none.
YAML::Node child(const YAML::Node &node, const std::string &step, std::string &what) {
    if (node.IsMap()) {
        if (node[step])
            return node[step];
        what = "has no key '" + step + "' (there: " + keysOf(node) + ")";
        return YAML::Node(YAML::NodeType::Undefined);
    }
    if (node.IsSequence()) {
        if (const auto k = config::listIndex(step); k && *k < node.size())
            return node[*k];
        what = "is a list of " + std::to_string(node.size()) + ": no item '" + step + "'";
        return YAML::Node(YAML::NodeType::Undefined);
    }
    what = "is a single value: no '" + step + "' in it";
    return YAML::Node(YAML::NodeType::Undefined);
}

} // namespace

std::vector<std::string> pathSteps(const std::string &key) {
    if (key.empty())
        throw std::invalid_argument("empty key");
    if (key.back() == '.')
        throw std::invalid_argument("key '" + key + "' has an empty step");
    std::vector<std::string> steps;
    std::string step;
    std::istringstream in(key);
    while (std::getline(in, step, '.')) {
        if (step.empty())
            throw std::invalid_argument("key '" + key + "' has an empty step");
        steps.push_back(step);
    }
    return steps;
}

YAML::Node findAtPath(const YAML::Node &root, const std::string &key) {
    YAML::Node node = root;
    std::string what;
    for (const std::string &step : pathSteps(key)) {
        YAML::Node next = child(node, step, what);
        if (!next.IsDefined())
            return next;
        node.reset(next); // rebinds; `node = next` would assign into the tree
    }
    return node;
}

void setAtPath(YAML::Node &root, const std::string &key, const YAML::Node &value) {
    const std::vector<std::string> steps = pathSteps(key);
    YAML::Node node = root;
    std::string done, what;
    for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
        YAML::Node next = child(node, steps[k], what);
        if (!next.IsDefined())
            throw std::invalid_argument("key '" + key +
                                        "': " + (done.empty() ? "the scenario" : "'" + done + "'") +
                                        " " + what);
        node.reset(next);
        done += (done.empty() ? "" : ".") + steps[k];
    }
    const std::string &last = steps.back();
    if (node.IsSequence()) {
        const auto k = config::listIndex(last);
        if (!k || *k >= node.size())
            throw std::invalid_argument("key '" + key + "': '" + last + "' is not an index of '" +
                                        done + "', a list of " + std::to_string(node.size()));
        node[*k] = YAML::Clone(value);
    } else if (node.IsMap()) {
        node[last] = YAML::Clone(value);
    } else {
        throw std::invalid_argument("key '" + key + "': '" + done + "' is a single value");
    }
}

void absolutizeFilePaths(YAML::Node &root, const std::string &folder) {
    if (root.IsSequence()) {
        for (std::size_t k = 0; k < root.size(); ++k) {
            YAML::Node item = root[k];
            absolutizeFilePaths(item, folder);
        }
        return;
    }
    if (!root.IsMap())
        return;
    for (auto entry : root) {
        const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
        YAML::Node value = entry.second;
        if (value.IsScalar() && (key == "file" || key == "model" || key == "keys")) {
            const std::filesystem::path path = value.Scalar();
            const std::filesystem::path beside = std::filesystem::path(folder) / path;
            if (!path.empty() && path.is_relative() && std::filesystem::exists(beside))
                value = std::filesystem::absolute(beside).lexically_normal().string();
        } else {
            absolutizeFilePaths(value, folder);
        }
    }
}

std::string emitYaml(const YAML::Node &root) {
    YAML::Emitter out;
    out.SetIndent(2);
    out << root;
    return std::string(out.c_str()) + "\n";
}

std::string inlineText(const YAML::Node &value) {
    if (value.IsScalar())
        return value.Scalar();
    YAML::Emitter out;
    out.SetSeqFormat(YAML::Flow);
    out.SetMapFormat(YAML::Flow);
    out << value;
    return out.c_str();
}

} // namespace grainlink::study
