#pragma once
// CURVE encryption and authentication for runs that leave the loopback interface. Keys are Z85
// text in files `grainlink keygen` writes: <name>.key (public + secret, keep private) and
// <name>.pub (public only, safe to copy to the other hosts).
#include <string>
#include <vector>

namespace grainlink::coupling {

struct CurveKeyPair {
    std::string public_key; ///< Z85, 40 characters
    std::string secret_key; ///< Z85, 40 characters; empty in a .pub file
};

/// What the coordinator needs: its own pair and the public keys of participants it admits.
struct CurveServerKeys {
    CurveKeyPair coordinator;
    std::vector<std::string> allowed_participants; ///< Z85 public keys
};

/// What a participant needs: its own pair and the coordinator's public key.
struct CurveClientKeys {
    CurveKeyPair participant;
    std::string coordinator_public_key;
};

/// Whether this libzmq was built with CURVE (Debian's is, through libsodium).
bool curveAvailable();
CurveKeyPair generateKeyPair();
/// Writes <directory>/<name>.key (mode 0600) and <name>.pub; refuses to overwrite a .key file.
void writeKeyPair(const std::string &directory, const std::string &name, const CurveKeyPair &keys);
/// Reads a .key or .pub file; errors name the file and the line.
CurveKeyPair readKeyFile(const std::string &path);
/// coordinator.key plus every other <name>.pub in the directory.
CurveServerKeys loadServerKeys(const std::string &directory);
/// <participant>.key plus coordinator.pub.
CurveClientKeys loadClientKeys(const std::string &directory, const std::string &participant);

/// True for endpoints that stay on this machine: ipc://, inproc://, tcp on 127.0.0.1 / localhost /
/// ::1.
bool isLocalEndpoint(const std::string &endpoint);

} // namespace grainlink::coupling
