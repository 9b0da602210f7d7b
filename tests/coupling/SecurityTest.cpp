// CURVE against mistaken or hostile peers: a key admits only its own participant's name; a
// wrong key, another coordinator's key or CURVE on one side only fail at once with the reason on
// the participant's side and are counted on the coordinator's; key files are checked.
#include "CouplingFixtures.hpp"

#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>

using namespace grainlink::coupling;
using grainlink::examples::twoMassConfig;
namespace fs = std::filesystem;

using grainlink::testing::scratch;

namespace {

/// coordinator, mbs and soil keys in a fresh directory.
std::string runKeys(const std::string &name) {
    const std::string keys = scratch(name);
    for (const char *who : {"coordinator", "mbs", "soil"})
        writeKeyPair(keys, who, generateKeyPair());
    return keys;
}

CoordinatorConfig keyedRun(const std::optional<CurveServerKeys> &keys) {
    auto config =
        grainlink::testing::twoMassRun(SchemeKind::ExplicitSerial, "tcp://127.0.0.1:*", 0.01, 0.05);
    config.curve = keys;
    config.handshake_timeout_s = 2.0;
    return config;
}

/// Starts `coordinator` on a thread; its future holds its failure line.
std::future<std::string> failureLater(Coordinator &coordinator) {
    return std::async(std::launch::async, [&coordinator] {
        try {
            coordinator.run();
        } catch (const CouplingError &e) {
            return std::string(e.what());
        }
        return std::string("(the run did not fail)");
    });
}

/// Runs the multibody side as `name` with `curve` keys; its failure line.
std::string joinAs(const std::string &name, const std::string &endpoint,
                   const std::optional<CurveClientKeys> &curve) {
    auto c = twoMassConfig(Role::Multibody, name, endpoint);
    c.curve = curve;
    c.handshake_timeout_s = 30.0; // the point: it must not take that long to say why
    try {
        Participant p(c);
        p.initialize();
    } catch (const CouplingError &e) {
        return e.what();
    }
    return "(joined)";
}

void writeFile(const std::string &path, const std::string &text, mode_t mode = 0600) {
    std::ofstream(path) << text;
    ::chmod(path.c_str(), mode);
}

} // namespace

TEST_CASE("CURVE: a participant's key admits only its own name", "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string keys = runKeys("bound");
    Coordinator coordinator(keyedRun(loadServerKeys(keys)));
    auto failure = failureLater(coordinator);
    // The soil's key, used to say Hello as 'mbs'.
    const std::string refused =
        "says Hello as 'mbs' with the CURVE key of 'soil' (each participant joins with its own "
        "<name>.key)";
    CHECK(joinAs("mbs", coordinator.boundEndpoint(), loadClientKeys(keys, "soil")) ==
          "participant 'mbs': the coordinator refused: " + refused);
    CHECK(failure.get() == "participant 'mbs', 'soil' failed during the handshake: did not join "
                           "within handshake_timeout_s = 2 s (a Hello as 'mbs' was refused: " +
                               refused + ")");
}

TEST_CASE("CURVE: a key the coordinator does not know is refused, and the client says so at once",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string keys = runKeys("unknown"), other = scratch("unknown-other");
    fs::copy(keys + "/coordinator.pub", other + "/coordinator.pub");
    writeKeyPair(other, "mbs", generateKeyPair());
    const CurveClientKeys stranger = loadClientKeys(other, "mbs");
    Coordinator coordinator(keyedRun(loadServerKeys(keys)));
    auto failure = failureLater(coordinator);
    CHECK(joinAs("mbs", coordinator.boundEndpoint(), stranger) ==
          "participant 'mbs': the coordinator at " + coordinator.boundEndpoint() +
              " refused this participant's CURVE key (public key " +
              stranger.participant.public_key +
              ", status 400): no <name>.pub in its keys directory holds it");
    CHECK_THAT(failure.get(),
               Catch::StartsWith("participant 'mbs', 'soil' failed during the handshake: did not "
                                 "join within handshake_timeout_s = 2 s (") &&
                   Catch::Contains("connection(s) refused by CURVE authentication: ") &&
                   Catch::Contains(" with a public key not among the participants' (last " +
                                   stranger.participant.public_key + ")"));
}

TEST_CASE("CURVE on one side only, or another coordinator's key: told at once",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string keys = runKeys("one-sided");
    // Whichever side notices a mechanism mismatch first names it, the other side sees the
    // connection break off: each side's message covers both.
    SECTION("a participant without keys, a coordinator with CURVE") {
        Coordinator coordinator(keyedRun(loadServerKeys(keys)));
        auto failure = failureLater(coordinator);
        const std::string at = "participant 'mbs': the coordinator at " +
                               coordinator.boundEndpoint() + " requires CURVE";
        const std::string or_at = "participant 'mbs': the handshake with the coordinator at " +
                                  coordinator.boundEndpoint() +
                                  " failed 3 times without a reason: the coordinator requires "
                                  "CURVE (give this participant its <name>.key and "
                                  "coordinator.pub), or no grainlink coordinator listens there";
        CHECK_THAT(joinAs("mbs", coordinator.boundEndpoint(), std::nullopt),
                   Catch::Equals(at + " and this participant has no keys (give it its "
                                      "<name>.key and coordinator.pub)") ||
                       Catch::Equals(or_at));
        CHECK_THAT(failure.get(),
                   Catch::Contains("connection(s) refused by CURVE authentication: ") &&
                       (Catch::Contains(" without CURVE") ||
                        Catch::Contains(" breaking off the handshake")));
    }
    SECTION("a participant with keys, a coordinator without CURVE") {
        Coordinator coordinator(keyedRun(std::nullopt));
        auto failure = failureLater(coordinator);
        CHECK_THAT(joinAs("mbs", coordinator.boundEndpoint(), loadClientKeys(keys, "mbs")),
                   Catch::Equals("participant 'mbs': this participant has CURVE keys but the "
                                 "coordinator at " +
                                 coordinator.boundEndpoint() + " runs without CURVE") ||
                       Catch::Equals("participant 'mbs': the handshake with the coordinator at " +
                                     coordinator.boundEndpoint() +
                                     " failed 3 times without a reason: the coordinator runs "
                                     "without CURVE, or coordinator.pub is not its public key"));
        failure.get();
    }
    SECTION("a participant that holds another coordinator's public key") {
        const std::string other = scratch("one-sided-other");
        writeKeyPair(other, "coordinator", generateKeyPair());
        fs::copy(keys + "/mbs.key", other + "/mbs.key");
        Coordinator coordinator(keyedRun(loadServerKeys(keys)));
        auto failure = failureLater(coordinator);
        CHECK(joinAs("mbs", coordinator.boundEndpoint(), loadClientKeys(other, "mbs")) ==
              "participant 'mbs': the handshake with the coordinator at " +
                  coordinator.boundEndpoint() +
                  " failed 3 times without a reason: the coordinator runs without CURVE, or "
                  "coordinator.pub is not its public key");
        CHECK_THAT(failure.get(), Catch::Contains(" encrypting for another coordinator key"));
    }
}

TEST_CASE("CURVE: every participant of the run needs its .pub", "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string keys = runKeys("missing-pub");
    fs::remove(keys + "/soil.pub");
    CHECK_THROWS_WITH(Coordinator(keyedRun(loadServerKeys(keys))),
                      "participant 'soil' has no public key: the CURVE keys directory needs its "
                      "soil.pub (`grainlink keygen`)");
}

TEST_CASE("Key files: the secret is private from its first byte, and never written through a "
          "link",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string dir = scratch("write");
    const mode_t old_umask = ::umask(0); // a umask that would leave a new file world-readable
    writeKeyPair(dir, "mbs", generateKeyPair());
    ::umask(old_umask);
    struct stat status {};
    REQUIRE(::stat((dir + "/mbs.key").c_str(), &status) == 0);
    CHECK((status.st_mode & 0777) == 0600);
    // A dangling link where the .key goes: refused, and nothing written where it points.
    const std::string target = dir + "/elsewhere.key";
    fs::create_symlink(target, dir + "/soil.key");
    CHECK_THROWS_WITH(writeKeyPair(dir, "soil", generateKeyPair()),
                      Catch::EndsWith("soil.key exists; remove it first to make a new key"));
    CHECK_FALSE(fs::exists(target));
}

TEST_CASE("Key files: malformed or world-readable ones are refused naming the file and line",
          "[coupling][security]") {
    if (!curveAvailable()) {
        WARN("libzmq without CURVE: skipped");
        return;
    }
    const std::string dir = scratch("read");
    const CurveKeyPair pair = generateKeyPair(), other = generateKeyPair();
    const std::string pub = "public_key: \"" + pair.public_key + "\"\n";
    const std::string secret = "secret_key: \"" + pair.secret_key + "\"\n";
    const std::string file = dir + "/mbs.key";
    const auto error = [&](const std::string &text, mode_t mode = 0600) {
        writeFile(file, text, mode);
        try {
            readKeyFile(file);
        } catch (const CouplingError &e) {
            return std::string(e.what());
        }
        return std::string("(read)");
    };
    CHECK(error("# comment\n" + pub + secret) == "(read)");
    CHECK(error("# comment\npublic_key \"x\"\n") ==
          file + ":2: expected `public_key: \"...\"` or `secret_key: \"...\"`");
    CHECK(error("public_key: \"short\"\n") ==
          file + ":1: public_key is not a 40-character Z85 key");
    CHECK(error("public_key: \"" + std::string(39, 'a') + "~\"\n") ==
          file + ":1: public_key is not a 40-character Z85 key"); // '~' is no Z85 digit
    CHECK(error(pub + "colour: \"" + pair.public_key + "\"\n") ==
          file + ":2: unknown key 'colour'");
    CHECK(error(pub + pub) == file + ":2: public_key given twice");
    CHECK(error(secret) == file + ": no public_key");
    CHECK(error("public_key: \"" + other.public_key + "\"\n" + secret) ==
          file + ": public_key is not the public key of its secret_key");
    CHECK(error(pub + secret, 0644) ==
          file +
              " holds a secret key but is readable by others (mode 0644): make it private "
              "with `chmod 600 " +
              file + "`");
    CHECK(error(pub + secret, 0640) != "(read)");
    CHECK(error(pub, 0644) == "(read)"); // a public key alone may be read by anyone

    // Server side: a .pub with a secret in it, and two names with one key.
    const std::string server = scratch("server");
    writeKeyPair(server, "coordinator", generateKeyPair());
    writeFile(server + "/mbs.pub", pub + secret);
    CHECK_THROWS_WITH(loadServerKeys(server),
                      server + "/mbs.pub holds a secret_key: a .pub file is shared, so it must "
                               "hold the public key only");
    writeFile(server + "/mbs.pub", pub, 0644);
    writeFile(server + "/soil.pub", pub, 0644);
    CHECK_THROWS_WITH(loadServerKeys(server),
                      Catch::Contains(".pub hold the same public key (a key admits one "
                                      "participant)"));
    writeFile(server + "/soil.pub", "public_key: \"" + other.public_key + "\"\n", 0644);
    const CurveServerKeys keys = loadServerKeys(server);
    CHECK(keys.allowed_participants ==
          std::map<std::string, std::string>{{"mbs", pair.public_key}, {"soil", other.public_key}});
}
