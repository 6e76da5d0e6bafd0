// The authenticated bus's core alone: what it signs is accepted once, and
// anything altered, moved, replayed, stale, unsigned or from a role the
// policy does not allow is refused; keys and keyrings that cannot be used
// are clear errors.
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "ofn/bus_auth/authenticator.hpp"

namespace ofn::bus_auth {
namespace {

constexpr int64_t kNow = 1'800'000'000'000'000;  // µs since the epoch

PublishPolicy test_policy() {
  return PublishPolicy::parse(
      "publishers:\n"
      "  onboard1: [NAV_STATE, HEARTBEAT_*]\n"
      "  onboard2: [REF_TRAJ]\n"
      "  gcs: [MISSION]\n",
      "test policy");
}

// Three roles with their keys; every authenticator shares the same clock.
struct Deployment {
  std::map<std::string, KeyPair> pairs;
  int64_t now = kNow;

  Deployment() {
    for (const char* role : {"onboard1", "onboard2", "gcs"}) pairs[role] = generate_key_pair();
  }
  std::map<std::string, PublicKey> public_keys() const {
    std::map<std::string, PublicKey> keys;
    for (const auto& [name, pair] : pairs) keys[name] = pair.public_key;
    return keys;
  }
  /// Signs as `role` with `secret` (its own by default), under `policy`.
  Authenticator as(const std::string& role, PublishPolicy policy = test_policy(),
                   std::map<std::string, PublicKey> keys = {}, const SecretKey* secret = nullptr) {
    if (keys.empty()) keys = public_keys();
    return Authenticator(role, secret ? *secret : pairs.at(role).secret_key, keys, policy,
                         [this] { return now; });
  }
};

std::vector<uint8_t> payload(size_t size, uint8_t seed = 7) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = static_cast<uint8_t>(seed + 31 * i);
  return bytes;
}

TEST(BusAuthenticator, SignedMessageIsAcceptedOnceWithItsPayload) {
  Deployment deployment;
  auto planner = deployment.as("onboard2");
  auto controller = deployment.as("onboard1");
  auto message = payload(300);
  planner.seal("REF_TRAJ", message);
  ASSERT_EQ(message.size(), 300 + kTrailerBytes);
  EXPECT_TRUE(ends_with_trailer(message.data(), message.size()));

  const auto opened = controller.open("REF_TRAJ", message.data(), message.size());
  EXPECT_TRUE(opened.authentic) << opened.reason;
  EXPECT_EQ(opened.payload_size, 300u);
  EXPECT_EQ(opened.role, "onboard2");
  EXPECT_EQ(std::vector<uint8_t>(message.begin(), message.begin() + 300), payload(300));

  // The same bytes again: a replay.
  const auto again = controller.open("REF_TRAJ", message.data(), message.size());
  EXPECT_FALSE(again.authentic);
  EXPECT_NE(again.reason.find("replayed"), std::string::npos) << again.reason;
}

TEST(BusAuthenticator, SequencesIncreaseEvenWithinOneMicrosecond) {
  Deployment deployment;
  auto planner = deployment.as("onboard2");
  auto controller = deployment.as("onboard1");
  for (int i = 0; i < 5; ++i) {
    auto message = payload(40, static_cast<uint8_t>(i));
    planner.seal("REF_TRAJ", message);
    EXPECT_TRUE(controller.open("REF_TRAJ", message.data(), message.size()).authentic) << i;
  }
}

TEST(BusAuthenticator, AnyAlteredByteIsRefused) {
  Deployment deployment;
  auto planner = deployment.as("onboard2");
  auto message = payload(64);
  planner.seal("REF_TRAJ", message);
  // Every byte but the magic (whose change makes it "not signed").
  int refused = 0;
  for (size_t i = 0; i + kTrailerMagic.size() < message.size(); ++i) {
    auto controller = deployment.as("onboard1");
    auto altered = message;
    altered[i] ^= 0x01;
    const auto opened = controller.open("REF_TRAJ", altered.data(), altered.size());
    EXPECT_FALSE(opened.authentic) << "byte " << i;
    refused += !opened.authentic;
  }
  EXPECT_EQ(refused, static_cast<int>(message.size() - kTrailerMagic.size()));
}

TEST(BusAuthenticator, MessageMovedToAnotherChannelIsRefused) {
  Deployment deployment;
  auto vehicle = deployment.as("onboard1");
  auto receiver = deployment.as("onboard2");
  auto message = payload(80);
  vehicle.seal("HEARTBEAT_CONTROLLER", message);
  // Both channels are onboard1's; the signature binds the channel.
  const auto moved = receiver.open("HEARTBEAT_VEHICLE_SIM", message.data(), message.size());
  EXPECT_FALSE(moved.authentic);
  EXPECT_NE(moved.reason.find("bad signature"), std::string::npos) << moved.reason;
  EXPECT_TRUE(receiver.open("HEARTBEAT_CONTROLLER", message.data(), message.size()).authentic);
}

TEST(BusAuthenticator, RoleMayPublishOnlyItsOwnChannels) {
  Deployment deployment;
  auto ground = deployment.as("gcs");
  auto controller = deployment.as("onboard1");
  // The ground station's own signer refuses to sign a plan at all.
  auto message = payload(50);
  EXPECT_THROW(ground.seal("REF_TRAJ", message), KeyError);

  // Signed with the ground station's key by hand (a compromised or
  // misconfigured ground station): refused by the policy.
  PublishPolicy lax = test_policy();
  lax.allow("gcs", "REF_TRAJ");
  auto forger = deployment.as("gcs", lax);
  auto forged = payload(50);
  forger.seal("REF_TRAJ", forged);
  const auto opened = controller.open("REF_TRAJ", forged.data(), forged.size());
  EXPECT_FALSE(opened.authentic);
  EXPECT_NE(opened.reason.find("may not publish"), std::string::npos) << opened.reason;
}

TEST(BusAuthenticator, ClaimingAnotherRoleFailsTheSignature) {
  Deployment deployment;
  auto controller = deployment.as("onboard1");
  // The ground station signs with its own key but writes "onboard2" as the
  // role: the signature does not verify under onboard2's public key.
  auto keys = deployment.public_keys();
  keys["onboard2"] = deployment.pairs.at("gcs").public_key;  // to pass its own key check
  auto impostor =
      deployment.as("onboard2", test_policy(), keys, &deployment.pairs.at("gcs").secret_key);
  auto message = payload(50);
  impostor.seal("REF_TRAJ", message);
  const auto opened = controller.open("REF_TRAJ", message.data(), message.size());
  EXPECT_FALSE(opened.authentic);
  EXPECT_NE(opened.reason.find("bad signature"), std::string::npos) << opened.reason;
}

TEST(BusAuthenticator, UnsignedTruncatedAndUnknownRolesAreRefused) {
  Deployment deployment;
  auto controller = deployment.as("onboard1");
  const auto plain = payload(200);
  EXPECT_EQ(controller.open("REF_TRAJ", plain.data(), plain.size()).reason, "not signed");
  EXPECT_EQ(controller.open("REF_TRAJ", plain.data(), 3).reason, "not signed");
  EXPECT_EQ(controller.open("REF_TRAJ", nullptr, 0).reason, "not signed");

  auto planner = deployment.as("onboard2");
  auto message = payload(30);
  planner.seal("REF_TRAJ", message);
  // Cut from the front: the trailer is intact but the payload is not.
  std::vector<uint8_t> cut(message.begin() + 1, message.end());
  EXPECT_FALSE(controller.open("REF_TRAJ", cut.data(), cut.size()).authentic);
  // A role name nobody has.
  auto renamed = message;
  std::memcpy(renamed.data() + 30, "intruder\0\0\0\0\0\0\0\0", kRoleBytes);
  EXPECT_EQ(controller.open("REF_TRAJ", renamed.data(), renamed.size()).reason,
            "signed by an unknown role");
}

TEST(BusAuthenticator, StaleAndFutureSequencesAreRefused) {
  Deployment deployment;
  auto planner = deployment.as("onboard2");
  auto message = payload(30);
  planner.seal("REF_TRAJ", message);
  for (const int64_t shift : {-2'500'000, 2'500'000}) {
    auto controller = deployment.as("onboard1");
    deployment.now = kNow + shift;
    const auto opened = controller.open("REF_TRAJ", message.data(), message.size());
    EXPECT_FALSE(opened.authentic) << shift;
    EXPECT_NE(opened.reason.find("freshness"), std::string::npos) << opened.reason;
  }
  // Within the window it is accepted.
  auto controller = deployment.as("onboard1");
  deployment.now = kNow + 1'500'000;
  EXPECT_TRUE(controller.open("REF_TRAJ", message.data(), message.size()).authentic);
}

TEST(BusAuthenticator, RestartedPublisherGoesOnAboveItsOldSequence) {
  Deployment deployment;
  auto controller = deployment.as("onboard1");
  auto first = deployment.as("onboard2");
  for (int i = 0; i < 3; ++i) {
    auto message = payload(20);
    first.seal("REF_TRAJ", message);
    ASSERT_TRUE(controller.open("REF_TRAJ", message.data(), message.size()).authentic);
  }
  deployment.now += 1000;  // a millisecond later the planner is back
  auto restarted = deployment.as("onboard2");
  auto message = payload(20);
  restarted.seal("REF_TRAJ", message);
  EXPECT_TRUE(controller.open("REF_TRAJ", message.data(), message.size()).authentic);
}

TEST(BusAuthenticator, MismatchedKeysAreRefusedAtConstruction) {
  Deployment deployment;
  const auto& gcs_secret = deployment.pairs.at("gcs").secret_key;
  EXPECT_THROW(deployment.as("onboard1", test_policy(), {}, &gcs_secret), KeyError);
  EXPECT_THROW(deployment.as("nobody", test_policy(), {}, &gcs_secret), KeyError);
}

TEST(PublishPolicy, PatternsAndErrors) {
  const auto policy = test_policy();
  EXPECT_TRUE(policy.may_publish("onboard1", "NAV_STATE"));
  EXPECT_TRUE(policy.may_publish("onboard1", "HEARTBEAT_MAPPER"));
  EXPECT_FALSE(policy.may_publish("onboard1", "NAV_STATE_X"));
  EXPECT_FALSE(policy.may_publish("gcs", "REF_TRAJ"));
  EXPECT_FALSE(policy.may_publish("stranger", "MISSION"));
  EXPECT_EQ(policy.roles(), (std::vector<std::string>{"gcs", "onboard1", "onboard2"}));

  EXPECT_THROW(PublishPolicy::parse("publishers: []", "p"), KeyError);
  EXPECT_THROW(PublishPolicy::parse("publishers: {gcs: []}", "p"), KeyError);
  EXPECT_THROW(PublishPolicy::parse("publishers: {'a b': [X]}", "p"), KeyError);
  EXPECT_THROW(PublishPolicy::parse("publisher: {gcs: [X]}", "p"), KeyError);
  EXPECT_THROW(PublishPolicy::parse("publishers: {gcs: [X]}\nextra: 1", "p"), KeyError);
  EXPECT_THROW(PublishPolicy::parse("{", "p"), KeyError);
}

TEST(PublishPolicy, ProjectPolicyKeepsTheGroundStationOffTheFlightChannels) {
  const auto policy = PublishPolicy::load(OFN_SOURCE_DIR "/config/bus_policy.yaml");
  EXPECT_EQ(policy.roles(), (std::vector<std::string>{"gcs", "onboard1", "onboard2"}));
  for (const char* channel : {"REF_TRAJ", "ACTUATOR_CMD", "NAV_STATE", "SIM_CLOCK", "OBSTACLE_GRID",
                              "GLOBAL_PATH", "HEARTBEAT_CONTROLLER"})
    EXPECT_FALSE(policy.may_publish("gcs", channel)) << channel;
  EXPECT_TRUE(policy.may_publish("gcs", "MISSION"));
  EXPECT_TRUE(policy.may_publish("onboard2", "REF_TRAJ"));
  EXPECT_TRUE(policy.may_publish("onboard1", "ACTUATOR_CMD"));
  EXPECT_FALSE(policy.may_publish("onboard2", "ACTUATOR_CMD"));
}

class Keyring : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ofn_bus_auth_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "policy.yaml") << "publishers:\n  a: [X]\n  b: [Y]\n";
    for (const char* role : {"a", "b"}) {
      const auto pair = generate_key_pair();
      write_public_key(path(std::string(role) + ".pub"), pair.public_key);
      write_secret_key(path(std::string(role) + ".key"), pair.secret_key);
    }
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static int64_t now() { return kNow; }

  std::filesystem::path dir_;
};

TEST_F(Keyring, LoadsAndTwoRolesTalk) {
  auto a = load_authenticator(dir_.string(), "a", now);
  auto b = load_authenticator(dir_.string(), "b", now);
  auto message = payload(10);
  a.seal("X", message);
  EXPECT_TRUE(b.open("X", message.data(), message.size()).authentic);
  struct stat info {};
  ASSERT_EQ(::stat(path("a.key").c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
}

// A reader of a recording holds no secret key: the keyring's public half
// checks what each role signed, and refuses the same as a host does.
TEST_F(Keyring, AVerifierNeedsOnlyThePublicHalf) {
  auto a = load_authenticator(dir_.string(), "a", now);
  auto b = load_authenticator(dir_.string(), "b", now);
  std::filesystem::remove(path("a.key"));
  std::filesystem::remove(path("b.key"));
  auto verifier = load_verifier(dir_.string(), now);
  auto on_x = payload(10), on_y = payload(10);
  a.seal("X", on_x);
  b.seal("Y", on_y);
  EXPECT_TRUE(verifier.open("X", on_x.data(), on_x.size()).authentic);
  EXPECT_TRUE(verifier.open("Y", on_y.data(), on_y.size()).authentic);
  EXPECT_EQ(verifier.open("X", on_x.data(), on_x.size()).reason,
            "replayed (sequence not newer than the last accepted)");
  auto forged = payload(10);
  a.seal("X", forged);
  EXPECT_EQ(verifier.open("Y", forged.data(), forged.size()).reason,
            "role 'a' may not publish here");
  forged[0] ^= 1;
  EXPECT_EQ(verifier.open("X", forged.data(), forged.size()).reason,
            "bad signature (altered, or signed with another key)");
  const auto unsigned_message = payload(10);
  EXPECT_EQ(verifier.open("X", unsigned_message.data(), unsigned_message.size()).reason,
            "not signed");
  std::filesystem::remove(path("b.pub"));
  EXPECT_THROW(load_verifier(dir_.string(), now), KeyError);
}

TEST_F(Keyring, SayWhatIsWrong) {
  const auto message_of = [&](const std::string& role) -> std::string {
    try {
      load_authenticator(dir_.string(), role, now);
    } catch (const KeyError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message_of("c").find("not in"), std::string::npos);
  EXPECT_NE(message_of("bad role!").find("must be"), std::string::npos);

  ::chmod(path("a.key").c_str(), 0644);
  EXPECT_NE(message_of("a").find("chmod 600"), std::string::npos) << message_of("a");
  ::chmod(path("a.key").c_str(), 0600);

  std::ofstream(path("b.pub")) << "not hex\n";
  EXPECT_NE(message_of("a").find("hex digits"), std::string::npos) << message_of("a");
  std::filesystem::remove(path("b.pub"));
  EXPECT_NE(message_of("a").find("cannot read public key"), std::string::npos);
  std::filesystem::remove(path("policy.yaml"));
  EXPECT_NE(message_of("a").find("cannot read publish policy"), std::string::npos);
}

TEST(TrailerDecode, PayloadAloneOrWithTrailerOnly) {
  // A stand-in for an lcm-gen type: decodes its first `length` bytes.
  struct FixedMessage {
    int length;
    int decode(const void*, int, int maxlen) { return maxlen < length ? -1 : length; }
  };
  Deployment deployment;
  auto signer = deployment.as("onboard2");
  auto message = payload(24);
  signer.seal("REF_TRAJ", message);
  FixedMessage fixed{24};
  EXPECT_TRUE(decode_payload(fixed, message.data(), 24));
  EXPECT_TRUE(decode_payload(fixed, message.data(), message.size()));
  EXPECT_FALSE(decode_payload(fixed, message.data(), 25));
  EXPECT_FALSE(decode_payload(fixed, message.data(), 23));
  auto no_magic = message;
  no_magic.pop_back();
  no_magic.push_back('X');
  EXPECT_FALSE(decode_payload(fixed, no_magic.data(), no_magic.size()));
}

TEST(TrailerDecode, TheSequenceTrailerAloneOrBeforeTheSignature) {
  struct FixedMessage {
    int length;
    int decode(const void*, int, int maxlen) { return maxlen < length ? -1 : length; }
  };
  FixedMessage fixed{24};
  auto numbered = payload(24);
  append_sequence_trailer(numbered, {0x0102030405060708ULL, 42});
  ASSERT_EQ(numbered.size(), 24 + kSequenceTrailerBytes);
  ASSERT_TRUE(ends_with_sequence_trailer(numbered.data(), numbered.size()));
  Trailers trailers;
  ASSERT_TRUE(decode_payload(fixed, numbered.data(), numbered.size(), &trailers));
  EXPECT_TRUE(trailers.sequenced);
  EXPECT_FALSE(trailers.signed_);
  EXPECT_EQ(trailers.sequence.publisher, 0x0102030405060708ULL);
  EXPECT_EQ(trailers.sequence.sequence, 42u);
  // Big endian, as the authentication trailer's fields.
  EXPECT_EQ(numbered[24], 0x01);
  EXPECT_EQ(numbered[24 + 15], 42);

  // Signed after it: the signature covers the sequence trailer.
  Deployment deployment;
  auto signer = deployment.as("onboard2");
  auto sealed = numbered;
  signer.seal("REF_TRAJ", sealed);
  ASSERT_EQ(sealed.size(), 24 + kMaxTrailerBytes);
  trailers = {};
  ASSERT_TRUE(decode_payload(fixed, sealed.data(), sealed.size(), &trailers));
  EXPECT_TRUE(trailers.sequenced);
  EXPECT_TRUE(trailers.signed_);
  EXPECT_EQ(trailers.sequence.sequence, 42u);
  auto controller = deployment.as("onboard1");
  const Opened opened = controller.open("REF_TRAJ", sealed.data(), sealed.size());
  ASSERT_TRUE(opened.authentic) << opened.reason;
  EXPECT_EQ(opened.payload_size, numbered.size());
  // A signed message without a sequence trailer (an older recording).
  auto signed_only = payload(24);
  deployment.now += 10;
  signer.seal("REF_TRAJ", signed_only);
  trailers = {};
  ASSERT_TRUE(decode_payload(fixed, signed_only.data(), signed_only.size(), &trailers));
  EXPECT_FALSE(trailers.sequenced);
  EXPECT_TRUE(trailers.signed_);
  // Not after the signature, and not a sequence trailer cut short.
  auto wrong_order = signed_only;
  append_sequence_trailer(wrong_order, {1, 1});
  EXPECT_FALSE(decode_payload(fixed, wrong_order.data(), wrong_order.size()));
  EXPECT_FALSE(decode_payload(fixed, numbered.data(), numbered.size() - 1));

  // The payload alone, by the magic: what a comparison of payloads reads.
  EXPECT_EQ(payload_bytes(sealed.data(), sealed.size()), 24u);
  EXPECT_EQ(payload_bytes(numbered.data(), numbered.size()), 24u);
  EXPECT_EQ(payload_bytes(signed_only.data(), signed_only.size()), 24u);
}

TEST(TrailerDecode, APayloadThatEndsLikeATrailerIsNotCut) {
  // A message whose own last bytes spell the magic, with nothing after it:
  // the decoder says where it ends, so no trailer is read.
  struct FixedMessage {
    int length;
    int decode(const void*, int, int maxlen) { return maxlen < length ? -1 : length; }
  };
  std::vector<uint8_t> bytes = payload(40);
  std::memcpy(bytes.data() + 36, kSequenceTrailerMagic.data(), 4);
  FixedMessage whole{40};
  Trailers trailers;
  ASSERT_TRUE(decode_payload(whole, bytes.data(), bytes.size(), &trailers));
  EXPECT_FALSE(trailers.sequenced);
}

}  // namespace
}  // namespace ofn::bus_auth
