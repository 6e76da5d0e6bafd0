// The hang watchdog's ears: every heartbeat heard becomes one line for the
// launcher, anything else on a heartbeat channel is refused and counted.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/tools/heartbeat_probe.hpp"

namespace ofn::report {
namespace {

heartbeat_t beat(const std::string& service, int32_t pid, int64_t utime) {
  heartbeat_t hb{};
  hb.utime = utime;
  hb.service = service;
  hb.pid = pid;
  hb.state = "running";
  return hb;
}

std::vector<uint8_t> encoded(const heartbeat_t& hb) {
  std::vector<uint8_t> bytes(static_cast<size_t>(hb.getEncodedSize()));
  hb.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

std::string heard(HeartbeatProbe& probe, const std::string& channel,
                  const std::vector<uint8_t>& bytes) {
  return probe.line(channel, bytes.data(), bytes.size());
}

TEST(HeartbeatProbe, AHeartbeatBecomesOneLine) {
  HeartbeatProbe probe;
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", encoded(beat("mapper", 4242, 12500000))),
            "heartbeat HEARTBEAT_MAPPER 4242 12500000");
  EXPECT_EQ(probe.heard(), 1);
  EXPECT_EQ(probe.refused(), 0);
}

TEST(HeartbeatProbe, WhatIsNoHeartbeatIsRefusedAndCounted) {
  HeartbeatProbe probe;
  const auto good = encoded(beat("mapper", 1, 0));
  EXPECT_EQ(heard(probe, "NAV_STATE", good), "");
  EXPECT_EQ(heard(probe, "HEARTBEAT_", good), "");
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAP PER", good), "");  // one word for the launcher
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", std::vector<uint8_t>(good.begin(), good.end() - 3)),
            "");
  EXPECT_EQ(probe.last_reason(), "HEARTBEAT_MAPPER: undecodable");
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", encoded(beat("", 1, 0))), "");
  EXPECT_EQ(probe.last_reason(), "HEARTBEAT_MAPPER: no service name");
  // Over the heartbeats' cap (4 KiB), whatever the bytes.
  auto big = beat("mapper", 1, 0);
  big.last_reject_reason = std::string(5000, 'x');
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", encoded(big)), "");
  EXPECT_EQ(probe.last_reason(), "HEARTBEAT_MAPPER: oversized");
  EXPECT_EQ(probe.refused(), 6);
  EXPECT_EQ(probe.heard(), 0);
}

TEST(HeartbeatProbe, OnAnAuthenticatedBusOnlySignedHeartbeatsAreHeard) {
  const auto policy = bus_auth::PublishPolicy::parse(
      "publishers:\n  onboard2: [HEARTBEAT_MAPPER]\n  gcs: [HEARTBEAT_VIEWER]\n", "test policy");
  std::map<std::string, bus_auth::KeyPair> pairs;
  std::map<std::string, bus_auth::PublicKey> keys;
  for (const char* role : {"onboard2", "gcs"}) {
    pairs[role] = bus_auth::generate_key_pair();
    keys[role] = pairs[role].public_key;
  }
  const int64_t wall = 1'800'000'000'000'000;
  const auto now = [wall] { return wall; };
  bus_auth::Authenticator onboard2("onboard2", pairs["onboard2"].secret_key, keys, policy, now);
  bus_auth::Authenticator gcs("gcs", pairs["gcs"].secret_key, keys, policy, now);
  HeartbeatProbe probe(bus_auth::Verifier(keys, policy, now));

  const auto plain = encoded(beat("mapper", 7, 1000000));
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", plain), "");
  EXPECT_EQ(probe.last_reason(), "HEARTBEAT_MAPPER: unauthenticated: not signed");
  auto signed_bytes = plain;
  onboard2.seal("HEARTBEAT_MAPPER", signed_bytes);
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", signed_bytes), "heartbeat HEARTBEAT_MAPPER 7 1000000");
  // The ground station may not speak for the mapper: a hung mapper's
  // heartbeats cannot be forged from there.
  auto forged = encoded(beat("mapper", 7, 2000000));
  bus_auth::Authenticator gcs_anywhere(
      "gcs", pairs["gcs"].secret_key, keys,
      bus_auth::PublishPolicy::parse("publishers:\n  gcs: [HEARTBEAT_*]\n", "forger's policy"),
      now);
  gcs_anywhere.seal("HEARTBEAT_MAPPER", forged);
  EXPECT_EQ(heard(probe, "HEARTBEAT_MAPPER", forged), "");
  EXPECT_EQ(probe.heard(), 1);
  EXPECT_EQ(probe.refused(), 2);
}

}  // namespace
}  // namespace ofn::report
