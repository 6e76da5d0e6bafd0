#include "ofn/bus_auth/authenticator.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <sodium.h>
#include <yaml-cpp/yaml.h>

namespace ofn::bus_auth {
namespace {

// Signed bytes start with a domain tag so that a signature made for this
// bus cannot be taken for one made for anything else under the same key.
constexpr char kDomainTag[] = "ofn-bus-auth-v1";

void init_sodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium could not be initialised");
}

template <size_t N>
std::string to_hex(const std::array<uint8_t, N>& bytes) {
  std::string hex(2 * N + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), bytes.data(), N);
  hex.resize(2 * N);
  return hex;
}

template <size_t N>
std::array<uint8_t, N> read_hex_key(const std::string& path, const char* what) {
  std::ifstream in(path);
  if (!in) throw KeyError(std::string("cannot read ") + what + " '" + path + "'");
  std::string line;
  std::getline(in, line);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  std::array<uint8_t, N> key{};
  size_t length = 0;
  if (line.size() != 2 * N ||
      sodium_hex2bin(key.data(), N, line.data(), line.size(), nullptr, &length, nullptr) != 0 ||
      length != N)
    throw KeyError(std::string(what) + " '" + path + "' is not " + std::to_string(2 * N) +
                   " hex digits on one line (make a keyring with ofn_bus_keygen)");
  return key;
}

void write_text(const std::string& path, const std::string& text, mode_t mode) {
  // Created with its final mode, so a secret key is never readable by others,
  // not even for a moment.
  ::unlink(path.c_str());
  FILE* file = nullptr;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, mode);
  if (fd >= 0) file = ::fdopen(fd, "w");
  if (!file) throw KeyError("cannot write '" + path + "': " + std::strerror(errno));
  const bool written = std::fputs(text.c_str(), file) >= 0;
  if (std::fclose(file) != 0 || !written)
    throw KeyError("cannot write '" + path + "': " + std::strerror(errno));
}

bool matches(const std::string& pattern, const std::string& channel) {
  if (!pattern.empty() && pattern.back() == '*')
    return channel.compare(0, pattern.size() - 1, pattern, 0, pattern.size() - 1) == 0;
  return pattern == channel;
}

// The bytes a signature covers: tag, channel, NUL, payload (with its
// sequence trailer), role, sequence.
void signed_bytes(const std::string& channel, const uint8_t* payload, size_t payload_size,
                  const uint8_t* role_and_sequence, std::vector<uint8_t>& out) {
  out.clear();
  out.reserve(sizeof(kDomainTag) + channel.size() + 1 + payload_size + kRoleBytes + kSequenceBytes);
  out.insert(out.end(), kDomainTag, kDomainTag + sizeof(kDomainTag));
  out.insert(out.end(), channel.begin(), channel.end());
  out.push_back(0);
  out.insert(out.end(), payload, payload + payload_size);
  out.insert(out.end(), role_and_sequence, role_and_sequence + kRoleBytes + kSequenceBytes);
}

}  // namespace

bool valid_role(const std::string& role) {
  return !role.empty() && role.size() <= kRoleBytes &&
         std::all_of(role.begin(), role.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
         });
}

KeyPair generate_key_pair() {
  init_sodium();
  KeyPair pair;
  crypto_sign_keypair(pair.public_key.data(), pair.secret_key.data());
  return pair;
}

void write_public_key(const std::string& path, const PublicKey& key) {
  write_text(path, to_hex(key) + "\n", 0644);
}

void write_secret_key(const std::string& path, const SecretKey& key) {
  write_text(path, to_hex(key) + "\n", 0600);
}

PublicKey read_public_key(const std::string& path) {
  return read_hex_key<kPublicKeyBytes>(path, "public key");
}

SecretKey read_secret_key(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0)
    throw KeyError("cannot read secret key '" + path + "': " + std::strerror(errno));
  if ((info.st_mode & 077) != 0) {
    std::ostringstream mode;
    mode << std::oct << (info.st_mode & 0777);
    throw KeyError("secret key '" + path + "' may be read by others (mode 0" + mode.str() +
                   "): chmod 600 '" + path + "'");
  }
  return read_hex_key<kSecretKeyBytes>(path, "secret key");
}

PublishPolicy PublishPolicy::parse(const std::string& yaml_text, const std::string& shown) {
  YAML::Node doc;
  try {
    doc = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw KeyError(shown + ": not valid YAML: " + e.what());
  }
  if (!doc.IsMap() || !doc["publishers"] || !doc["publishers"].IsMap())
    throw KeyError(shown + ": expected a mapping 'publishers: {ROLE: [CHANNEL, ...]}'");
  for (const auto& entry : doc) {
    if (entry.first.as<std::string>() != "publishers")
      throw KeyError(shown + ": unknown field '" + entry.first.as<std::string>() +
                     "' (expected 'publishers')");
  }
  PublishPolicy policy;
  for (const auto& entry : doc["publishers"]) {
    const auto role = entry.first.as<std::string>();
    if (!valid_role(role))
      throw KeyError(shown + ": role '" + role + "' must be 1-16 letters, digits, '_' or '-'");
    if (!entry.second.IsSequence() || entry.second.size() == 0)
      throw KeyError(shown + ": publishers." + role + " must be a non-empty list of channels");
    for (const auto& channel : entry.second) {
      if (!channel.IsScalar() || channel.as<std::string>().empty())
        throw KeyError(shown + ": publishers." + role + " holds a channel that is not a name");
      policy.allow(role, channel.as<std::string>());
    }
  }
  if (policy.patterns_.empty()) throw KeyError(shown + ": no role may publish anything");
  return policy;
}

PublishPolicy PublishPolicy::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw KeyError("cannot read publish policy '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

void PublishPolicy::allow(const std::string& role, const std::string& pattern) {
  patterns_[role].push_back(pattern);
}

bool PublishPolicy::may_publish(const std::string& role, const std::string& channel) const {
  const auto found = patterns_.find(role);
  if (found == patterns_.end()) return false;
  return std::any_of(found->second.begin(), found->second.end(),
                     [&](const std::string& pattern) { return matches(pattern, channel); });
}

std::vector<std::string> PublishPolicy::roles() const {
  std::vector<std::string> roles;
  for (const auto& entry : patterns_) roles.push_back(entry.first);
  return roles;
}

Verifier::Verifier(std::map<std::string, PublicKey> public_keys, PublishPolicy policy,
                   std::function<int64_t()> wall_now_us, double freshness)
    : public_keys_(std::move(public_keys)),
      policy_(std::move(policy)),
      wall_now_us_(std::move(wall_now_us)),
      freshness_us_(static_cast<int64_t>(std::llround(freshness * 1e6))) {
  init_sodium();
  if (!(freshness > 0) || !std::isfinite(freshness))
    throw KeyError("freshness must be a positive number of seconds");
  if (!wall_now_us_) throw KeyError("no wall clock given");
}

Authenticator::Authenticator(std::string role, const SecretKey& secret_key,
                             std::map<std::string, PublicKey> public_keys, PublishPolicy policy,
                             std::function<int64_t()> wall_now_us, double freshness)
    : role_(std::move(role)),
      secret_key_(secret_key),
      wall_now_us_(wall_now_us),
      verifier_(std::move(public_keys), std::move(policy), std::move(wall_now_us), freshness) {
  if (!valid_role(role_))
    throw KeyError("role '" + role_ + "' must be 1-16 letters, digits, '_' or '-'");
  // The secret key holds its public half: it must be the one the others
  // check against, or everything this host says would be refused.
  const auto own = verifier_.public_keys().find(role_);
  if (own == verifier_.public_keys().end())
    throw KeyError("the keyring holds no public key of role '" + role_ + "'");
  if (std::memcmp(own->second.data(), secret_key_.data() + 32, kPublicKeyBytes) != 0)
    throw KeyError("the secret key of role '" + role_ + "' does not belong to its public key");
}

void Authenticator::seal(const std::string& channel, std::vector<uint8_t>& message) {
  if (!may_publish(channel))
    throw KeyError("role '" + role_ + "' may not publish on " + channel +
                   " (the keyring's policy.yaml)");
  // Sequences are wall-clock microseconds, kept strictly increasing, so a
  // restarted publisher goes on above what it sent before.
  const auto now = static_cast<uint64_t>(std::max<int64_t>(0, wall_now_us_()));
  last_sent_ = std::max(last_sent_ + 1, now);
  std::array<uint8_t, kRoleBytes + kSequenceBytes> role_and_sequence{};
  std::memcpy(role_and_sequence.data(), role_.data(), role_.size());
  put_be64(role_and_sequence.data() + kRoleBytes, last_sent_);
  signed_bytes(channel, message.data(), message.size(), role_and_sequence.data(), scratch_);
  std::array<uint8_t, kSignatureBytes> signature{};
  crypto_sign_detached(signature.data(), nullptr, scratch_.data(), scratch_.size(),
                       secret_key_.data());
  message.insert(message.end(), role_and_sequence.begin(), role_and_sequence.end());
  message.insert(message.end(), signature.begin(), signature.end());
  message.insert(message.end(), kTrailerMagic.begin(), kTrailerMagic.end());
}

Opened Verifier::open(const std::string& channel, const void* data, size_t size) {
  Opened result;
  if (!ends_with_trailer(data, size)) {
    result.reason = "not signed";
    return result;
  }
  const auto* bytes = static_cast<const uint8_t*>(data);
  const size_t payload_size = size - kTrailerBytes;
  const uint8_t* role_field = bytes + payload_size;
  const size_t role_length =
      std::find(role_field, role_field + kRoleBytes, uint8_t{0}) - role_field;
  const std::string role(reinterpret_cast<const char*>(role_field), role_length);
  const auto key = public_keys_.find(role);
  if (!valid_role(role) || key == public_keys_.end()) {
    result.reason = "signed by an unknown role";
    return result;
  }
  result.role = role;
  if (!policy_.may_publish(role, channel)) {
    result.reason = "role '" + role + "' may not publish here";
    return result;
  }
  const uint64_t sequence = get_be64(role_field + kRoleBytes);
  const int64_t age = wall_now_us_() - static_cast<int64_t>(sequence);
  if (sequence > static_cast<uint64_t>(INT64_MAX) || age > freshness_us_ || age < -freshness_us_) {
    result.reason = "sequence outside the freshness window (old, replayed or clocks apart)";
    return result;
  }
  const auto last = last_accepted_.find({role, channel});
  if (last != last_accepted_.end() && sequence <= last->second) {
    result.reason = "replayed (sequence not newer than the last accepted)";
    return result;
  }
  signed_bytes(channel, bytes, payload_size, role_field, scratch_);
  const uint8_t* signature = role_field + kRoleBytes + kSequenceBytes;
  if (crypto_sign_verify_detached(signature, scratch_.data(), scratch_.size(),
                                  key->second.data()) != 0) {
    result.reason = "bad signature (altered, or signed with another key)";
    return result;
  }
  last_accepted_[{role, channel}] = sequence;
  result.authentic = true;
  result.payload_size = payload_size;
  return result;
}

namespace {

/// The keyring's policy and the public keys of all its roles.
std::pair<PublishPolicy, std::map<std::string, PublicKey>> load_public_half(
    const std::string& dir) {
  auto policy = PublishPolicy::load(dir + "policy.yaml");
  std::map<std::string, PublicKey> public_keys;
  for (const auto& r : policy.roles()) public_keys[r] = read_public_key(dir + r + ".pub");
  return {std::move(policy), std::move(public_keys)};
}

std::string as_directory(const std::string& keyring_dir) {
  return keyring_dir.empty() || keyring_dir.back() == '/' ? keyring_dir : keyring_dir + "/";
}

}  // namespace

Authenticator load_authenticator(const std::string& keyring_dir, const std::string& role,
                                 std::function<int64_t()> wall_now_us) {
  if (!valid_role(role))
    throw KeyError("--bus-role '" + role + "' must be 1-16 letters, digits, '_' or '-'");
  const std::string dir = as_directory(keyring_dir);
  auto [policy, public_keys] = load_public_half(dir);
  const auto roles = policy.roles();
  if (std::find(roles.begin(), roles.end(), role) == roles.end()) {
    std::string known;
    for (const auto& r : roles) known += (known.empty() ? "" : ", ") + r;
    throw KeyError("role '" + role + "' is not in " + dir + "policy.yaml (roles: " + known + ")");
  }
  const auto secret = read_secret_key(dir + role + ".key");
  return Authenticator(role, secret, std::move(public_keys), std::move(policy),
                       std::move(wall_now_us));
}

Verifier load_verifier(const std::string& keyring_dir, std::function<int64_t()> wall_now_us) {
  auto [policy, public_keys] = load_public_half(as_directory(keyring_dir));
  return Verifier(std::move(public_keys), std::move(policy), std::move(wall_now_us));
}

}  // namespace ofn::bus_auth
