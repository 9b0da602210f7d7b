#pragma once
// CURVE encryption and authentication for runs that leave the loopback interface. Keys are Z85
// text in files `grainlink keygen` writes: <name>.key (public + secret, keep private) and
// <name>.pub (public only, safe to copy to the other hosts).
#include <map>
#include <string>

namespace grainlink::coupling {

struct CurveKeyPair {
    std::string public_key; ///< Z85, 40 characters
    std::string secret_key; ///< Z85, 40 characters; empty in a .pub file
};

/// What the coordinator needs: its own pair and the public keys of participants it admits.
struct CurveServerKeys {
    CurveKeyPair coordinator;
    /// participant name → its Z85 public key (from <name>.pub); a connection with that key may
    /// join as that participant only
    std::map<std::string, std::string> allowed_participants;
};

/// What a participant needs: its own pair and the coordinator's public key.
struct CurveClientKeys {
    CurveKeyPair participant;
    std::string coordinator_public_key;
};

/// Whether this libzmq was built with CURVE (Debian's is, through libsodium).
bool curveAvailable();
CurveKeyPair generateKeyPair();
/// Writes <directory>/<name>.key (created with mode 0600, so the secret is never readable by
/// others) and <name>.pub; refuses to overwrite a .key file or to follow a link in its place.
void writeKeyPair(const std::string &directory, const std::string &name, const CurveKeyPair &keys);
/// Reads a .key or .pub file; errors name the file and the line. A file with a secret key must
/// be private to its owner (mode 0600, as `grainlink keygen` writes it), hold valid Z85 keys, and
/// its public key must be the one of its secret key.
CurveKeyPair readKeyFile(const std::string &path);
/// coordinator.key plus every other <name>.pub in the directory, by name; two names with one key
/// are an error.
CurveServerKeys loadServerKeys(const std::string &directory);
/// <participant>.key plus coordinator.pub.
CurveClientKeys loadClientKeys(const std::string &directory, const std::string &participant);

/// True for endpoints that stay on this machine: ipc://, inproc://, tcp on 127.0.0.1 / localhost /
/// ::1.
bool isLocalEndpoint(const std::string &endpoint);

} // namespace grainlink::coupling
