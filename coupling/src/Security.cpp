#include "grainlink/coupling/Security.hpp"

#include "grainlink/coupling/Types.hpp"

#include <zmq.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace grainlink::coupling {

namespace fs = std::filesystem;

bool curveAvailable() {
    return zmq_has("curve") != 0;
}

CurveKeyPair generateKeyPair() {
    if (!curveAvailable())
        throw CouplingError("this libzmq has no CURVE support (it needs libsodium)");
    char public_key[41], secret_key[41];
    if (zmq_curve_keypair(public_key, secret_key) != 0)
        throw CouplingError(std::string("zmq_curve_keypair failed: ") + zmq_strerror(zmq_errno()));
    return CurveKeyPair{public_key, secret_key};
}

void writeKeyPair(const std::string &directory, const std::string &name, const CurveKeyPair &keys) {
    fs::create_directories(directory);
    const fs::path secret = fs::path(directory) / (name + ".key");
    const fs::path pub = fs::path(directory) / (name + ".pub");
    if (fs::exists(secret))
        throw CouplingError(secret.string() + " exists; remove it first to make a new key");
    {
        std::ofstream out(secret);
        out << "# grainlink CURVE key pair of '" << name << "' (Z85). Keep this file private.\n"
            << "public_key: \"" << keys.public_key << "\"\n"
            << "secret_key: \"" << keys.secret_key << "\"\n";
        if (!out)
            throw CouplingError("cannot write " + secret.string());
    }
    ::chmod(secret.c_str(), S_IRUSR | S_IWUSR);
    std::ofstream out(pub);
    out << "# grainlink CURVE public key of '" << name << "' (Z85). Safe to share.\n"
        << "public_key: \"" << keys.public_key << "\"\n";
    if (!out)
        throw CouplingError("cannot write " + pub.string());
}

CurveKeyPair readKeyFile(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw CouplingError("cannot open key file " + path);
    CurveKeyPair keys;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.empty() || line[0] == '#')
            continue;
        const auto colon = line.find(':');
        const auto open = line.find('"'), close = line.rfind('"');
        if (colon == std::string::npos || open == std::string::npos || close <= open)
            throw CouplingError(path + ":" + std::to_string(number) +
                                ": expected `public_key: \"...\"` or `secret_key: \"...\"`");
        const std::string key = line.substr(0, colon);
        const std::string value = line.substr(open + 1, close - open - 1);
        if (value.size() != 40)
            throw CouplingError(path + ":" + std::to_string(number) + ": " + key +
                                " is not a 40-character Z85 key");
        if (key == "public_key")
            keys.public_key = value;
        else if (key == "secret_key")
            keys.secret_key = value;
        else
            throw CouplingError(path + ":" + std::to_string(number) + ": unknown key '" + key +
                                "'");
    }
    if (keys.public_key.empty())
        throw CouplingError(path + ": no public_key");
    return keys;
}

CurveServerKeys loadServerKeys(const std::string &directory) {
    CurveServerKeys keys;
    keys.coordinator = readKeyFile((fs::path(directory) / "coordinator.key").string());
    if (keys.coordinator.secret_key.empty())
        throw CouplingError(directory + "/coordinator.key has no secret_key");
    for (const auto &entry : fs::directory_iterator(directory))
        if (entry.path().extension() == ".pub" && entry.path().stem() != "coordinator")
            keys.allowed_participants.push_back(readKeyFile(entry.path().string()).public_key);
    if (keys.allowed_participants.empty())
        throw CouplingError(directory + " holds no participant .pub files: no one could join");
    return keys;
}

CurveClientKeys loadClientKeys(const std::string &directory, const std::string &participant) {
    CurveClientKeys keys;
    keys.participant = readKeyFile((fs::path(directory) / (participant + ".key")).string());
    if (keys.participant.secret_key.empty())
        throw CouplingError(directory + "/" + participant + ".key has no secret_key");
    keys.coordinator_public_key =
        readKeyFile((fs::path(directory) / "coordinator.pub").string()).public_key;
    return keys;
}

bool isLocalEndpoint(const std::string &endpoint) {
    if (endpoint.rfind("ipc://", 0) == 0 || endpoint.rfind("inproc://", 0) == 0)
        return true;
    for (const char *host : {"tcp://127.0.0.1:", "tcp://localhost:", "tcp://[::1]:"})
        if (endpoint.rfind(host, 0) == 0)
            return true;
    return false;
}

} // namespace grainlink::coupling
