#include "grainlink/coupling/Security.hpp"

#include "grainlink/coupling/Types.hpp"

#include <zmq.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

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
    // Created private (never readable by others, not even for a moment) and only if nothing,
    // not even a dangling link, is in its place.
    const int fd = ::open(secret.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0600);
    if (fd < 0)
        throw CouplingError(errno == EEXIST
                                ? secret.string() + " exists; remove it first to make a new key"
                                : "cannot create " + secret.string() + ": " + std::strerror(errno));
    const std::string text = "# grainlink CURVE key pair of '" + name +
                             "' (Z85). Keep this file private.\n" + "public_key: \"" +
                             keys.public_key + "\"\n" + "secret_key: \"" + keys.secret_key + "\"\n";
    const bool written = ::write(fd, text.data(), text.size()) == ssize_t(text.size());
    if (::close(fd) != 0 || !written)
        throw CouplingError("cannot write " + secret.string());
    std::ofstream out(pub);
    out << "# grainlink CURVE public key of '" << name << "' (Z85). Safe to share.\n"
        << "public_key: \"" << keys.public_key << "\"\n";
    if (!out)
        throw CouplingError("cannot write " + pub.string());
}

namespace {

bool validZ85Key(const std::string &text) {
    std::uint8_t bytes[32];
    return text.size() == 40 && zmq_z85_decode(bytes, text.c_str()) != nullptr;
}

} // namespace

CurveKeyPair readKeyFile(const std::string &path) {
    std::ifstream in(path);
    if (!in)
        throw CouplingError("cannot open key file " + path);
    CurveKeyPair keys;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.empty() || line[0] == '#')
            continue;
        const std::string at = path + ":" + std::to_string(number) + ": ";
        const auto colon = line.find(':');
        const auto open = line.find('"'), close = line.rfind('"');
        if (colon == std::string::npos || open == std::string::npos || close <= open)
            throw CouplingError(at + "expected `public_key: \"...\"` or `secret_key: \"...\"`");
        const std::string key = line.substr(0, colon);
        const std::string value = line.substr(open + 1, close - open - 1);
        std::string *slot = key == "public_key"   ? &keys.public_key
                            : key == "secret_key" ? &keys.secret_key
                                                  : nullptr;
        if (!slot)
            throw CouplingError(at + "unknown key '" + key + "'");
        if (!slot->empty())
            throw CouplingError(at + key + " given twice");
        if (!validZ85Key(value))
            throw CouplingError(at + key + " is not a 40-character Z85 key");
        *slot = value;
    }
    if (keys.public_key.empty())
        throw CouplingError(path + ": no public_key");
    if (!keys.secret_key.empty()) {
        struct stat status {};
        if (::stat(path.c_str(), &status) == 0 && (status.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
            char mode[8];
            std::snprintf(mode, sizeof mode, "%04o", unsigned(status.st_mode & 07777));
            throw CouplingError(path + " holds a secret key but is readable by others (mode " +
                                mode + "): make it private with `chmod 600 " + path + "`");
        }
        char derived[41];
        if (zmq_curve_public(derived, keys.secret_key.c_str()) != 0 || keys.public_key != derived)
            throw CouplingError(path + ": public_key is not the public key of its secret_key");
    }
    return keys;
}

namespace {

/// A .pub file's key. Such files are copied to other hosts, so one holding a secret is refused.
std::string readPublicKey(const fs::path &path) {
    const CurveKeyPair pair = readKeyFile(path.string());
    if (!pair.secret_key.empty())
        throw CouplingError(path.string() + " holds a secret_key: a .pub file is shared, so it "
                                            "must hold the public key only");
    return pair.public_key;
}

} // namespace

CurveServerKeys loadServerKeys(const std::string &directory) {
    CurveServerKeys keys;
    keys.coordinator = readKeyFile((fs::path(directory) / "coordinator.key").string());
    if (keys.coordinator.secret_key.empty())
        throw CouplingError(directory + "/coordinator.key has no secret_key");
    std::map<std::string, std::string> name_by_key;
    for (const auto &entry : fs::directory_iterator(directory)) {
        const fs::path &path = entry.path();
        if (path.extension() != ".pub" || path.stem() == "coordinator")
            continue;
        const std::string key = readPublicKey(path), name = path.stem().string();
        if (const auto [it, fresh] = name_by_key.emplace(key, name); !fresh)
            throw CouplingError(directory + ": " + it->second + ".pub and " + name +
                                ".pub hold the same public key (a key admits one participant)");
        keys.allowed_participants[name] = key;
    }
    if (keys.allowed_participants.empty())
        throw CouplingError(directory + " holds no participant .pub files: no one could join");
    return keys;
}

CurveClientKeys loadClientKeys(const std::string &directory, const std::string &participant) {
    CurveClientKeys keys;
    keys.participant = readKeyFile((fs::path(directory) / (participant + ".key")).string());
    if (keys.participant.secret_key.empty())
        throw CouplingError(directory + "/" + participant + ".key has no secret_key");
    keys.coordinator_public_key = readPublicKey(fs::path(directory) / "coordinator.pub");
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
