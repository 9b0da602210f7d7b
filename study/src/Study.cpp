#include "grainlink/study/Study.hpp"

#include "Executors.hpp"
#include "grainlink/dem/Deposition.hpp"
#include "grainlink/study/ScenarioEdit.hpp"
#include "grainlink/study/StudyFolder.hpp"

#include <filesystem>

#include <set>
#include <stdexcept>

namespace grainlink::study {

Point makePoint(const Kind &kind, const std::string &scenario_yaml, const std::string &label) {
    Point p;
    p.kind = kind;
    p.scenario_yaml = scenario_yaml;
    p.label = label;
    p.origin = label;
    // 12 of the 16 hex digits: short folder names, and collisions need ~10^7 points.
    p.id = dem::hashKey(kind.name + "\n" + scenario_yaml).substr(0, 12);
    try {
        const YAML::Node threads = findAtPath(YAML::Load(scenario_yaml), kind.threads_key);
        p.threads = threads.IsDefined() ? threads.as<int>() : 1;
    } catch (const YAML::Exception &) {
        p.threads = 1; // the validator reports what is wrong with the text
    }
    return p;
}

void validate(const Study &study) {
    std::set<std::string> ids;
    for (const Point &p : study.points) {
        if (!ids.insert(p.id).second)
            throw std::invalid_argument("study '" + study.name + "': point '" + p.label +
                                        "' is the same scenario as an earlier point (" + p.id +
                                        ")");
        if (!p.kind.validate)
            throw std::invalid_argument("study '" + study.name + "': kind '" + p.kind.name +
                                        "' has no scenario reader to check point '" + p.label +
                                        "' with");
        // Named after the file the run would read, so the reader's line numbers point into it.
        const std::string path = StudyFolder(study.directory).scenarioPath(p);
        try {
            p.kind.validate(config::ConfigNode::loadString(p.scenario_yaml, path));
        } catch (const std::exception &e) {
            // The refused scenario is the one file written: the message points into it.
            std::filesystem::create_directories(std::filesystem::path(path).parent_path());
            writeFileAtomically(path, p.scenario_yaml);
            throw std::invalid_argument(p.origin + ": not a valid " + p.kind.name +
                                        " scenario: " + e.what());
        }
    }
}

std::vector<PointResult> collect(const Study &study) {
    const StudyFolder folder(study.directory);
    std::vector<PointResult> results;
    for (const Point &p : study.points)
        results.push_back(folder.state(p));
    return results;
}

bool runsAgain(const PointResult &result, bool retry_failed) {
    return result.status == PointStatus::Unfinished ||
           (result.status == PointStatus::Failed && retry_failed);
}

std::vector<PointResult> run(const Study &study, const ExecutorOptions &options) {
    if (options.grainlink.empty())
        throw std::invalid_argument("ExecutorOptions::grainlink: name the grainlink executable");
    validate(study);
    const StudyFolder folder(study.directory);
    folder.write(study);
    std::vector<PointResult> results = collect(study);
    std::vector<std::size_t> todo;
    for (std::size_t k = 0; k < results.size(); ++k)
        if (runsAgain(results[k], options.retry_failed))
            todo.push_back(k);
    if (todo.empty())
        return results;
    if (options.executor == ExecutorOptions::Executor::Local)
        runLocal(study, folder, todo, options, results);
    else
        runSlurm(study, folder, todo, options, results);
    return results;
}

StudyProgress progressOf(const std::vector<PointResult> &results, std::size_t running,
                         const std::vector<double> &ran_s, int parallel,
                         std::chrono::steady_clock::time_point start) {
    StudyProgress p;
    p.total = results.size();
    p.running = running;
    for (const PointResult &r : results) {
        p.done += r.status == PointStatus::Done;
        p.failed += r.status == PointStatus::Failed;
        p.reused += r.status != PointStatus::Unfinished && !r.ran_now;
    }
    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!ran_s.empty()) {
        double sum = 0.0;
        for (double s : ran_s)
            sum += s;
        const double left = double(p.total - p.done - p.failed);
        p.eta_s = left * (sum / double(ran_s.size())) / double(std::max(parallel, 1));
    }
    return p;
}

} // namespace grainlink::study
