#pragma once
// The authenticated bus: every message a host publishes is signed with the
// host role's Ed25519 key (libsodium) and carries a sequence number (the
// sending host's wall clock, in microseconds); every receiver checks the
// signature against the role's public key, the role's right to publish on
// the channel (the publish policy) and that the sequence is fresh and newer
// than the last one it accepted from that role on that channel. The count
// of a publisher's messages that shows loss is the sequence trailer's
// (trailer.hpp), which the signature covers with the payload. Ed25519 rather than a shared HMAC
// key: a host holds only its own secret key, so the ground station cannot sign what only the
// onboard computers may publish (REF_TRAJ, ACTUATOR_CMD).
//
// Pure core: no LCM, no clock of its own (the caller gives wall time).
// Not thread-safe; a process uses it from its LCM loop.

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ofn/bus_auth/trailer.hpp"

namespace ofn::bus_auth {

/// A key, keyring or policy that cannot be used: a clear message for the
/// user (a usage error: programs exit with code 2).
class KeyError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

inline constexpr size_t kPublicKeyBytes = 32;
inline constexpr size_t kSecretKeyBytes = 64;
using PublicKey = std::array<uint8_t, kPublicKeyBytes>;
using SecretKey = std::array<uint8_t, kSecretKeyBytes>;

struct KeyPair {
  PublicKey public_key{};
  SecretKey secret_key{};
};

/// A new random key pair.
KeyPair generate_key_pair();

/// Key files hold one line of lower-case hex. A secret key file is written
/// with mode 0600 and refused when others may read it.
void write_public_key(const std::string& path, const PublicKey& key);
void write_secret_key(const std::string& path, const SecretKey& key);
PublicKey read_public_key(const std::string& path);
SecretKey read_secret_key(const std::string& path);

/// Which role may publish on which channel. A pattern is a channel name, or
/// a prefix ending in '*'.
class PublishPolicy {
 public:
  /// YAML: `publishers: {ROLE: [CHANNEL, PREFIX*, ...], ...}`. `shown` names
  /// the source in error messages.
  static PublishPolicy parse(const std::string& yaml_text, const std::string& shown);
  static PublishPolicy load(const std::string& path);

  void allow(const std::string& role, const std::string& pattern);
  bool may_publish(const std::string& role, const std::string& channel) const;
  std::vector<std::string> roles() const;

 private:
  std::map<std::string, std::vector<std::string>> patterns_;
};

/// A role name: 1-16 characters of letters, digits, '_' and '-'.
bool valid_role(const std::string& role);

/// Outcome of checking one received message.
struct Opened {
  bool authentic = false;
  /// Bytes before the authentication trailer (when authentic): the LCM
  /// payload and its sequence trailer, if it has one.
  size_t payload_size = 0;
  /// The signer's role (when the trailer names a known one).
  std::string role;
  /// Why it was refused, without numbers (counted by kind).
  std::string reason;
};

/// Checks received messages against the roles' public keys and the
/// publish policy. Holds no secret key: a host's receiving half, and all a
/// reader of a recording needs.
class Verifier {
 public:
  /// Accepts what the roles of `public_keys` sign on the channels `policy`
  /// gives them, stamped within `freshness` seconds of `wall_now_us()`
  /// (microseconds since the epoch; the hosts' clocks must agree that
  /// closely).
  Verifier(std::map<std::string, PublicKey> public_keys, PublishPolicy policy,
           std::function<int64_t()> wall_now_us, double freshness = 2.0);

  const PublishPolicy& policy() const { return policy_; }
  const std::map<std::string, PublicKey>& public_keys() const { return public_keys_; }

  /// Checks a received message. The replay record is updated only for an
  /// authentic one.
  Opened open(const std::string& channel, const void* data, size_t size);

 private:
  std::map<std::string, PublicKey> public_keys_;
  PublishPolicy policy_;
  std::function<int64_t()> wall_now_us_;
  int64_t freshness_us_;
  std::map<std::pair<std::string, std::string>, uint64_t> last_accepted_;
  std::vector<uint8_t> scratch_;
};

class Authenticator {
 public:
  /// Signs as `role` with `secret_key`; checks what it receives as a
  /// Verifier of the same arguments does.
  Authenticator(std::string role, const SecretKey& secret_key,
                std::map<std::string, PublicKey> public_keys, PublishPolicy policy,
                std::function<int64_t()> wall_now_us, double freshness = 2.0);

  const std::string& role() const { return role_; }
  /// Whether the policy lets this role publish on `channel`.
  bool may_publish(const std::string& channel) const {
    return verifier_.policy().may_publish(role_, channel);
  }

  /// Appends the trailer to `message` (an encoded LCM payload and its
  /// sequence trailer, ofn/bus_auth/trailer.hpp) for publication on
  /// `channel`; the signature covers every byte of it. Throws KeyError when the policy does not let
  /// this role publish there: a misconfigured deployment, found at once.
  void seal(const std::string& channel, std::vector<uint8_t>& message);

  /// Checks a received message (Verifier::open).
  Opened open(const std::string& channel, const void* data, size_t size) {
    return verifier_.open(channel, data, size);
  }

 private:
  std::string role_;
  SecretKey secret_key_;
  std::function<int64_t()> wall_now_us_;
  Verifier verifier_;
  uint64_t last_sent_ = 0;
  std::vector<uint8_t> scratch_;
};

/// A keyring directory, as ofn_bus_keygen writes it: policy.yaml, a public
/// key <role>.pub for every role of the policy and the secret key
/// <role>.key of at least the role that loads it (each host gets only its
/// own). Throws KeyError naming what is missing or wrong.
Authenticator load_authenticator(const std::string& keyring_dir, const std::string& role,
                                 std::function<int64_t()> wall_now_us);

/// A Verifier of a keyring directory's policy.yaml and public keys: what
/// the reader of a recording of that bus checks it with. Throws KeyError
/// naming what is missing or wrong.
Verifier load_verifier(const std::string& keyring_dir, std::function<int64_t()> wall_now_us);

}  // namespace ofn::bus_auth
