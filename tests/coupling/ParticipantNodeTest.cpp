// The one participant loop (coupling/ParticipantNode.hpp): it calls a node's hooks as the
// coordinator commands, window by window, and a node's failure reaches the coordinator as the
// node's own message, naming the participant and the window.
#include "CouplingFixtures.hpp"

#include <catch2/catch.hpp>

#include <functional>
#include <future>
#include <memory>

using namespace grainlink::coupling;
using grainlink::examples::MassOneNode;
using grainlink::examples::MassTwoNode;
using grainlink::examples::SideHooks;
using grainlink::examples::twoMassConfig;
using grainlink::examples::TwoMassNode;
using grainlink::testing::twoMassRun;

using grainlink::testing::failureOf;

namespace {

/// A two-mass side that logs every hook the loop calls: "start", "save", "restore",
/// "advance <window>.<iteration>", "finish".
class Recording final : public ParticipantNode {
public:
    Recording(std::unique_ptr<TwoMassNode> inner, std::vector<std::string> &log)
        : inner_(std::move(inner)), log_(log) {}
    void start(const RunInfo &run) override {
        log_.push_back("start");
        inner_->start(run);
    }
    WindowOutputs advance(const WindowInputs &in) override {
        log_.push_back("advance " + std::to_string(in.window) + "." + std::to_string(in.iteration));
        return inner_->advance(in);
    }
    void saveState() override {
        log_.push_back("save");
        inner_->saveState();
    }
    void restoreState() override {
        log_.push_back("restore");
        inner_->restoreState();
    }
    void finish() override { log_.push_back("finish"); }

private:
    std::unique_ptr<TwoMassNode> inner_;
    std::vector<std::string> &log_;
};

std::future<void> startRecorded(Role role, const std::string &endpoint,
                                std::vector<std::string> &log) {
    return std::async(std::launch::async, [role, endpoint, &log] {
        Participant p(twoMassConfig(role, role == Role::Multibody ? "mbs" : "soil", endpoint));
        std::unique_ptr<TwoMassNode> inner;
        if (role == Role::Multibody)
            inner = std::make_unique<MassOneNode>(p, grainlink::examples::TwoMassParameters{},
                                                  SideHooks{});
        else
            inner = std::make_unique<MassTwoNode>(p, grainlink::examples::TwoMassParameters{},
                                                  SideHooks{});
        Recording node(std::move(inner), log);
        runParticipant(p, node);
    });
}

} // namespace

TEST_CASE("The loop calls a node's hooks as the coordinator commands, window by window",
          "[coupling][loop]") {
    for (auto kind : {SchemeKind::ExplicitSerial, SchemeKind::Implicit}) {
        INFO(schemeName(kind));
        Coordinator coordinator(twoMassRun(kind, "tcp://127.0.0.1:*", 0.01, 0.05));
        std::vector<std::string> mbs_log, soil_log;
        auto mbs = startRecorded(Role::Multibody, coordinator.boundEndpoint(), mbs_log);
        auto soil = startRecorded(Role::Soil, coordinator.boundEndpoint(), soil_log);
        const auto summary = coordinator.run();
        mbs.get();
        soil.get();
        REQUIRE(summary.windows == 5);
        for (const auto *log : {&mbs_log, &soil_log}) {
            // start first, finish last; between them only passes over windows, each the next
            // window's first pass (iteration 0) or a repeat of the current one.
            REQUIRE(log->size() >= 2);
            CHECK(log->front() == "start");
            CHECK(log->back() == "finish");
            std::size_t window = 0, passes = 0;
            unsigned iteration = 0;
            for (std::size_t k = 1; k + 1 < log->size(); ++k) {
                const std::string &entry = (*log)[k];
                if (entry == "save" || entry == "restore")
                    continue;
                const std::string expected_next =
                    "advance " + std::to_string(passes ? window + 1 : 0) + ".0";
                const std::string expected_repeat =
                    "advance " + std::to_string(window) + "." + std::to_string(iteration + 1);
                INFO("entry " << k << ": " << entry);
                REQUIRE((entry == expected_next || (passes > 0 && entry == expected_repeat)));
                if (entry == expected_next) {
                    window = passes ? window + 1 : 0;
                    iteration = 0;
                } else {
                    ++iteration;
                }
                ++passes;
                // Implicit coupling: the state is saved before a window's first pass and rolled
                // back before each repeat; explicit coupling never does either.
                const std::string &before = (*log)[k - 1];
                if (kind == SchemeKind::Implicit)
                    CHECK(before == (iteration == 0 ? "save" : "restore"));
                else
                    CHECK((before != "save" && before != "restore"));
            }
            CHECK(window == 4);
            CHECK(passes == summary.iterations); // the coordinator's count of passes
        }
        if (kind == SchemeKind::Implicit)
            CHECK(summary.iterations > summary.windows); // the test saw repeats
    }
}

TEST_CASE("A node's exception stops the run with its own message, naming participant and window",
          "[coupling][loop]") {
    auto config = twoMassRun(SchemeKind::ExplicitSerial, "tcp://127.0.0.1:*", 0.01, 0.2);
    SECTION("the soil side throws") {
        Coordinator coordinator(config);
        SideHooks hooks;
        hooks.throw_at_window = 3;
        auto mbs = grainlink::testing::startSide(Role::Multibody, coordinator.boundEndpoint());
        auto soil = grainlink::testing::startSide(Role::Soil, coordinator.boundEndpoint(), hooks);
        CHECK(failureOf(coordinator) ==
              "participant 'soil' failed in window 3 (t = 0.03 s): reported: the model broke "
              "down at t = 0.030000 s (thrown at window 3)");
        // The node's own exception leaves runParticipant unchanged; the other side is told.
        CHECK(failureOf(soil) == "the model broke down at t = 0.030000 s (thrown at window 3)");
        CHECK_THAT(failureOf(mbs),
                   Catch::Contains("participant 'mbs': the coordinator stopped the run: "
                                   "participant 'soil' failed in window 3"));
    }
    SECTION("the multibody side throws") {
        Coordinator coordinator(config);
        SideHooks hooks;
        hooks.throw_at_window = 7;
        auto mbs =
            grainlink::testing::startSide(Role::Multibody, coordinator.boundEndpoint(), hooks);
        auto soil = grainlink::testing::startSide(Role::Soil, coordinator.boundEndpoint());
        CHECK(failureOf(coordinator) ==
              "participant 'mbs' failed in window 7 (t = 0.07 s): reported: the model broke "
              "down at t = 0.070000 s (thrown at window 7)");
        CHECK_THAT(failureOf(soil), Catch::Contains("the coordinator stopped the run"));
        CHECK_THAT(failureOf(mbs), Catch::StartsWith("the model broke down"));
    }
}

namespace {

/// Mass 1 at rest, except that its state turns non-finite in window `bad_window`.
class BrokenMultibody final : public ParticipantNode {
public:
    explicit BrokenMultibody(std::uint64_t bad_window) : bad_window_(bad_window) {}
    WindowOutputs advance(const WindowInputs &in) override {
        BodyState state;
        state.body = "mass1";
        if (in.window == bad_window_)
            state.position_m.x() = std::nan("");
        WindowOutputs out;
        out.states = {state};
        return out;
    }

private:
    std::uint64_t bad_window_;
};

} // namespace

TEST_CASE("What the participant refuses from a node is reported like the node's own failure",
          "[coupling][loop]") {
    Coordinator coordinator(twoMassRun(SchemeKind::ExplicitSerial, "tcp://127.0.0.1:*", 0.01, 0.2));
    auto mbs = std::async(std::launch::async, [endpoint = coordinator.boundEndpoint()] {
        Participant p(twoMassConfig(Role::Multibody, "mbs", endpoint));
        BrokenMultibody node(2);
        runParticipant(p, node);
    });
    auto soil = grainlink::testing::startSide(Role::Soil, coordinator.boundEndpoint());
    CHECK(failureOf(coordinator) == "participant 'mbs' failed in window 2 (t = 0.02 s): reported: "
                                    "participant 'mbs': non-finite state of body 'mass1' in "
                                    "window 2");
    CHECK_THAT(failureOf(mbs), Catch::Contains("non-finite state of body 'mass1'"));
    CHECK_THAT(failureOf(soil), Catch::Contains("the coordinator stopped the run"));
}
