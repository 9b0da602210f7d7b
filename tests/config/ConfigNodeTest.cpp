// Strict YAML reading: every error names the file, the key and the line; range rules refuse
// what is out of range with the range in the message. The references are the texts below.
#include "grainlink/config/ConfigNode.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using grainlink::config::ConfigError;
using grainlink::config::ConfigNode;
using Catch::Matchers::Contains;

namespace {
ConfigNode load(const std::string &text) { return ConfigNode::loadString(text, "s.yaml"); }
} // namespace

TEST_CASE("a missing key, an unknown key and a wrong unit name the file, key and line",
          "[config]") {
    const ConfigNode a = load("sim:\n  time_step_s: 1e-5\n  dt: 3\n");
    CHECK_THROWS_WITH(a["sim"]["end_time_s"], Contains("s.yaml:2: missing key 'sim.end_time_s'"));
    const ConfigNode sim = load("sim:\n  time_step_s: 1e-5\n  dt: 3\n")["sim"];
    (void)sim["time_step_s"].number();
    CHECK_THROWS_WITH(sim.finish(), Contains("s.yaml:3: unknown key 'sim.dt'"));
    const ConfigNode c = load("sim:\n  time_step_ms: 0.01\n");
    CHECK_THROWS_WITH(c["sim"]["time_step_s"],
                      Contains("s.yaml:2: unknown key 'sim.time_step_ms' (wrong unit?"));
    // A typo that shares a stem with a known key is no other unit of it.
    const ConfigNode u = load("u:\n  y_relative: 0.1\n  y_sigam: 2\n")["u"];
    (void)u["y_relative"].number();
    CHECK_THROWS_WITH(u.finish(),
                      Contains("s.yaml:3: unknown key 'u.y_sigam'") && !Contains("wrong unit"));
}

TEST_CASE("a misspelt key is named with the key it may stand for", "[config]") {
    // A required key written in another case: still missing (the other may be a key of its
    // own), with the likely typo and its line.
    const ConfigNode d = load("data:\n  files: [a]\n  X: {column: z}\n")["data"];
    CHECK_THROWS_WITH(d["x"], Contains("s.yaml:2: missing key 'data.x' ('X' at line 3 misspelt?)"));
    // One letter off an optional key that was read: the unknown key names it.
    const ConfigNode u = load("u:\n  repeat: rebuilt_bed\n")["u"];
    (void)u.optional("repeats");
    CHECK_THROWS_WITH(u.finish(), Contains("s.yaml:2: unknown key 'u.repeat' (misspelt? a key "
                                           "read here is 'repeats')"));
    // Short or different words are no typos of each other.
    const ConfigNode m = load("m:\n  y: 1\n")["m"];
    CHECK_THROWS_WITH(m["x"], Contains("missing key 'm.x'") && !Contains("misspelt"));
    using grainlink::config::misspelling;
    CHECK(misspelling("plate_diamter_m", "plate_diameter_m"));
    CHECK(misspelling("skip_line", "skip_lines"));
    CHECK_FALSE(misspelling("width_m", "depth_m"));
    CHECK(misspelling("x", "X"));       // case alone is a typo
    CHECK_FALSE(misspelling("x", "x")); // the same key is none
}

TEST_CASE("a key given twice is refused with both lines, whichever way it is read",
          "[config]") {
    const std::string text = "a: 1\nb: 2\na: 3\n";
    CHECK_THROWS_WITH(load(text)["a"], Contains("s.yaml:3: key 'a' given twice (first at line 1)"));
    CHECK_THROWS_WITH(load(text).optional("a"), Contains("given twice"));
    CHECK_THROWS_WITH(load(text).number("a", 0.0), Contains("given twice"));
    CHECK(load(text)["b"].number() == 2.0);
}

TEST_CASE("a list or a mapping as a key is refused with its line, not a bare yaml-cpp error",
          "[config]") {
    // YAML allows {[1, 2]: x}; the fuzzer found it escaping as "yaml-cpp: bad conversion".
    const std::string text = "contact:\n  tangential: {model: linear, [0.06, 0.3]}\n";
    const ConfigNode tangential = load(text)["contact"]["tangential"];
    const auto refused = Contains("s.yaml:2: a key of 'contact.tangential' is a list or a mapping");
    CHECK_THROWS_WITH(tangential.keys(), refused);
    CHECK_THROWS_WITH(tangential["stiffness_N_m"], refused); // missing: the unit hint scans keys
    (void)tangential["model"].text();
    CHECK_THROWS_WITH(tangential.finish(), refused);
}

TEST_CASE("range rules refuse out-of-range values naming the key, line and range",
          "[config]") {
    const ConfigNode n = load("zero: 0\nneg: -0.5\nfrac: 1.5\ncount: -5\nhuge: 1e9\nhalf: 2.5\n"
                              "list: [1, 2, -3]\nempty: []\nbig: 1e300\n");
    CHECK_THROWS_WITH(n["zero"].positive(), Contains("s.yaml:1: key 'zero': must be > 0, got 0"));
    CHECK(n["zero"].nonNegative() == 0.0);
    CHECK_THROWS_WITH(n["neg"].nonNegative(), Contains("s.yaml:2: key 'neg': must be >= 0, got -0.5"));
    CHECK(n["frac"].number(0.0, 2.0) == 1.5);
    CHECK_THROWS_WITH(n["frac"].number(0.0, 1.0), Contains("s.yaml:3: key 'frac': must be in [0, 1], got 1.5"));
    // A negative count no longer wraps to a huge unsigned one, and an absurd one stops here.
    CHECK_THROWS_WITH(n["count"].integer(1, 1000),
                      Contains("s.yaml:4: key 'count': must be a whole number in [1, 1000], got -5"));
    CHECK_THROWS_WITH(n["huge"].integer(1, 50000000), Contains("in [1, 50000000], got 1e9"));
    CHECK_THROWS_WITH(n["half"].integer(0, 10), Contains("expected a whole number, got 2.5"));
    CHECK_THROWS_WITH(n["big"].integer(), Contains("whole number out of range"));
    CHECK_THROWS_WITH(n["list"].positives(), Contains("s.yaml:7: key 'list[2]': must be > 0, got -3"));
    CHECK_THROWS_WITH(n["empty"].positives(), Contains("key 'empty': give at least one value"));
    CHECK(n.integer("absent", 1, 8, 4) == 4);
    CHECK_THROWS_WITH(n.integer("count", 0, 8, 4), Contains("in [0, 8], got -5"));
}

TEST_CASE("an empty file and a folder are refused with what they are", "[config]") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink-config-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string empty = (dir / "empty.yaml").string();
    std::ofstream(empty) << "";
    CHECK_THROWS_WITH(ConfigNode::loadFile(empty), Contains("empty.yaml:1: the file is empty"));
    CHECK_THROWS_WITH(ConfigNode::loadFile(dir.string()), Contains("is a folder, not a YAML file"));
    CHECK_THROWS_WITH(ConfigNode::loadFile((dir / "absent.yaml").string()),
                      Contains("absent.yaml: cannot open file"));
    const std::string bad = (dir / "bad.yaml").string();
    std::ofstream(bad) << "a: 1\nb: [1, 2\n";
    CHECK_THROWS_AS(ConfigNode::loadFile(bad), ConfigError);
    CHECK_THROWS_WITH(ConfigNode::loadFile(bad), Contains("bad.yaml:") && Contains("YAML syntax error"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("a key's list index is digits only, at most nine of them: a number too long for any "
          "list is no index, not an overflow",
          "[config]") {
    // The study fuzzer's finding (fuzz/regressions/study/index-too-long.txt): a varied key
    // `bodies.7777...70.motion` ended in std::stoul's out_of_range, which named no file.
    CHECK(grainlink::config::listIndex("0") == std::size_t(0));
    CHECK(grainlink::config::listIndex("12") == std::size_t(12));
    CHECK(grainlink::config::listIndex("999999999") == std::size_t(999999999));
    CHECK_FALSE(grainlink::config::listIndex("1000000000"));
    CHECK_FALSE(grainlink::config::listIndex(std::string(70, '7')));
    CHECK_FALSE(grainlink::config::listIndex(""));
    CHECK_FALSE(grainlink::config::listIndex("-1"));
    CHECK_FALSE(grainlink::config::listIndex("1e3"));
    CHECK_FALSE(grainlink::config::listIndex("plate"));
}

TEST_CASE("a number written with its unit is refused with the unit's place named", "[config]") {
    const ConfigNode c = load("conditions:\n  normal_stress_Pa: 20 kPa\n  depth_m: abc\n");
    CHECK_THROWS_WITH(c["conditions"]["normal_stress_Pa"].number(),
                      Contains("s.yaml:2: key 'conditions.normal_stress_Pa': expected a number, "
                               "got '20 kPa': give the number alone, in the unit its key's name "
                               "ends with"));
    // No number at all: no such hint.
    CHECK_THROWS_WITH(c["conditions"]["depth_m"].number(), !Contains("give the number alone"));
}
