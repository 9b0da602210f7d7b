// Observables are numbers at dotted paths of each run's summary; the table gives each design
// point's mean, sample standard deviation and standard error over its finished replicates.
#include "StudyFixtures.hpp"

#include "grainlink/study/ResultTable.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace grainlink::study;
using nlohmann::json;

TEST_CASE("an observable is the number at a dotted path of a summary, list items by index",
          "[study][results]") {
    const json summary = json::parse(R"({"fit": {"psi_deg": {"value": 31.5, "ci95": 1.25}},
        "bodies": {"plate": {"force_N": [0.5, -1.0, 4.0]}}, "name": "x", "ok": true})");
    CHECK(observable(summary, "fit.psi_deg.value") == 31.5);
    CHECK(observable(summary, "fit.psi_deg.ci95") == 1.25);
    CHECK(observable(summary, "bodies.plate.force_N.2") == 4.0);
    CHECK_FALSE(observable(summary, "bodies.plate.force_N.3"));
    CHECK_FALSE(observable(summary, "fit.psi_deg")); // an object, not a number
    CHECK_FALSE(observable(summary, "name"));        // text
    CHECK_FALSE(observable(summary, "fit.phi_deg.value"));
}

TEST_CASE("mean, sample standard deviation and standard error by hand", "[study][results]") {
    // 1, 2, 3, 4: mean 2.5, squares 2.25 + 0.25 + 0.25 + 2.25 = 5, sd = sqrt(5/3).
    const Statistics s = statistics({1.0, 2.0, 3.0, 4.0});
    CHECK(s.n == 4);
    CHECK(s.mean == Approx(2.5).epsilon(1e-15));
    CHECK(s.sd == Approx(1.2909944487358056).epsilon(1e-14));
    CHECK(s.sem == Approx(0.6454972243679028).epsilon(1e-14));
    const Statistics one = statistics({7.0});
    CHECK(one.mean == 7.0);
    CHECK(std::isnan(one.sd));
    CHECK(statistics({}).n == 0);
}

TEST_CASE("the table groups the replicates of a design point, failed points do not count",
          "[study][results]") {
    Study s;
    s.varied_keys = {"contact.tangential.stick_angle_deg"};
    s.replicate_key = "deposition.seed";
    s.observables = {"steady.slip.mean"};
    std::vector<PointResult> results;
    auto add = [&](const char *angle, const char *seed, PointStatus status, double slip) {
        PointResult r;
        r.point.settings = {{s.varied_keys[0], angle}, {s.replicate_key, seed}};
        r.status = status;
        r.summary = {{"steady", {{"slip", {{"mean", slip}}}}}};
        results.push_back(r);
    };
    add("30", "1", PointStatus::Done, 0.2);
    add("34", "1", PointStatus::Done, 0.5);
    add("30", "2", PointStatus::Done, 0.4);
    add("30", "3", PointStatus::Failed, 100.0);
    add("34", "2", PointStatus::Unfinished, 100.0);
    const std::vector<TableRow> rows = tableRows(s, results);
    REQUIRE(rows.size() == 2);
    CHECK(rows[0].settings == std::vector<std::string>{"30"});
    CHECK(rows[0].points == 3);
    CHECK(rows[0].finished == 2);
    CHECK(rows[0].observables[0].mean == Approx(0.3));
    CHECK(rows[0].observables[0].sd == Approx(std::sqrt(0.02)));
    CHECK(rows[1].finished == 1);
    CHECK(rows[1].observables[0].mean == 0.5);
    const std::string md = markdownTable(s, rows);
    CHECK_THAT(md, Catch::Contains("| contact.tangential.stick_angle_deg | finished | "
                                   "steady.slip.mean |"));
    CHECK_THAT(md, Catch::Contains("| 30 | 2/3 | 0.3 ± 0.1 (sd 0.14, n 2) |"));
    CHECK_THAT(md, Catch::Contains("| 34 | 1/2 | 0.5 |"));
}
