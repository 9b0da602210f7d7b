#pragma once
// The coupling subcommands of `grainlink`: coordinator, run, keygen.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/coupling/Coordinator.hpp"

#include <string>
#include <vector>

namespace grainlink::apps {

struct CoupledRunOptions {
    std::string config_path;
    std::string output_directory; ///< empty: out/<file stem>
    bool resume = false;
    bool insecure = false;
    std::string endpoint; ///< overrides the file's coupling.endpoint
    double progress_interval_s = 5.0;
};

/// A coupled scenario's coordinator configuration, with every participant's own section read
/// too (`grainlink run` and `grainlink study` check a file with it before starting anything).
coupling::CoordinatorConfig checkedCoupledConfig(const config::ConfigNode &root);
/// `grainlink coordinator`: only the coordinator; every participant is started by the user.
int runCoordinator(const CoupledRunOptions &options);
/// `grainlink run`: the coordinator plus the participant processes the file names.
int runCoupled(const CoupledRunOptions &options);
/// Checks the participant sections of the coupled scenario `root` (file `path`) against the
/// nodes its participant commands run, before any process starts: each section strictly, and a
/// section no node reads, or a second multibody model, is an error naming the key and the line.
void checkParticipantSections(const config::ConfigNode &root, const std::string &path);
/// After a mole's run on the DEM soil: each stroke in mbs_summary.json gets `depth_m`, the tip's
/// depth below the settled bed surface at the stroke's end (and the summary the last one).
/// After a single-wheel rig's run on the DEM soil (`directory` holds rig_summary.json and the
/// soil's series): adds the wheel's sinkage and the bin's end walls over the span the rig judged,
/// and refuses a steady state whose push the end wall it goes towards took more than
/// wheel_test.end_wall_limit of (steady false, the message says why). Returns whether the run
/// stands; a scenario without a rig or a judged span stands as it is.
bool addSoilMeasures(const config::ConfigNode &root, const std::string &directory);
/// `grainlink keygen`: CURVE key pairs for the coordinator and each named participant.
int generateKeys(const std::string &directory, const std::vector<std::string> &participants);

} // namespace grainlink::apps
