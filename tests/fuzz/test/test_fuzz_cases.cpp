// The bus fuzz's messages: every channel of the channel table has a
// generator, every field of every seed is hit with every value of its kind,
// and a Node refuses what it must (every truncation, wrong fingerprint,
// hostile size and string length, NaN and Inf in any float, stamp far from
// now) and survives the rest.

#include <gtest/gtest.h>

#include <cstring>

#include <map>
#include <memory>
#include <set>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channel_table.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/node.hpp"
#include "ofn/fuzz/fuzz_cases.hpp"

namespace ofn::fuzz {
namespace {

const Schema& project_schema() {
  static const Schema s = Schema::parse(builtin_lcm_sources());
  return s;
}

constexpr Utime kNow = 500 * 1000000LL;

std::map<std::string, std::vector<std::string>> heartbeat_names() {
  return {{"HEARTBEAT_", {"HEARTBEAT_FUZZ", "HEARTBEAT_CONTROLLER"}}};
}

Fuzzer table_fuzzer(uint64_t seed = 1) {
  return Fuzzer(project_schema(), channel_table(), message_supports(), heartbeat_names(), seed);
}

TEST(Fuzzer, EveryChannelOfTheTableHasAGenerator) {
  const Fuzzer fuzzer = table_fuzzer();
  const auto channels = fuzzer.channels();
  for (const auto& entry : channel_table()) {
    if (entry.prefix) continue;
    EXPECT_NE(std::find(channels.begin(), channels.end(), entry.name), channels.end())
        << entry.name;
  }
  EXPECT_NE(std::find(channels.begin(), channels.end(), "HEARTBEAT_CONTROLLER"), channels.end());
}

TEST(Fuzzer, AChannelWithoutAGeneratorStopsIt) {
  const std::vector<ChannelInfo> table = {{"NAV_STATE", "nav_state_t", 1024},
                                          {"NEW_CHANNEL", "new_thing_t", 1024}};
  try {
    Fuzzer(project_schema(), table, message_supports(), {}, 1);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("channel NEW_CHANNEL: no fuzz generator for new_thing_t"),
              std::string::npos)
        << e.what();
  }
  auto supports = message_supports();
  supports[0].fingerprint ^= 1;  // nav_state_t's, as if its .lcm file had changed
  EXPECT_THROW(Fuzzer(project_schema(), {table[0]}, supports, {}, 1), std::runtime_error);
  const std::vector<ChannelInfo> family = {{"HEARTBEAT_", "heartbeat_t", 4096, true}};
  EXPECT_THROW(Fuzzer(project_schema(), family, message_supports(), {}, 1), std::runtime_error);
}

TEST(Fuzzer, EveryPlaceOfEverySeedGetsEveryValueOfItsKind) {
  Fuzzer fuzzer = table_fuzzer();
  std::set<Kind> kinds;
  for (const auto& channel : fuzzer.channels()) {
    const auto messages = fuzzer.all_of(channel, kNow);
    EXPECT_EQ(messages.size(), fuzzer.cycle_length(channel));
    for (const auto& m : messages) kinds.insert(m.kind);
  }
  EXPECT_EQ(kinds.size(), static_cast<size_t>(kKindCount));
  // nav_state_t: 19 doubles, each with five non-finite values; one stamp
  // with eleven; every cut.
  std::map<Kind, int> nav;
  std::set<std::string> nan_places;
  for (const auto& m : fuzzer.all_of("NAV_STATE", kNow)) {
    ++nav[m.kind];
    if (m.kind == Kind::kNonFinite && m.what.size() > 6 &&
        m.what.compare(m.what.size() - 6, 6, " = NaN") == 0)
      nan_places.insert(m.what);
  }
  EXPECT_EQ(nav[Kind::kNonFinite], 19 * 5);
  EXPECT_EQ(nan_places.size(), 19u);
  EXPECT_EQ(nav[Kind::kStamp], 11);
  EXPECT_EQ(nav[Kind::kStringLength], 7);
  EXPECT_EQ(nav[Kind::kOversized], 1);
  // Every count of ref_traj_t (knots, control points, samples) with every
  // hostile size, up to 2^31 - 1.
  int sizes = 0;
  bool largest = false;
  for (const auto& m : fuzzer.all_of("REF_TRAJ", kNow)) {
    if (m.kind != Kind::kSizeField) continue;
    ++sizes;
    largest = largest || m.what.find("= 2147483647 ") != std::string::npos;
  }
  EXPECT_EQ(sizes, 3 * 9);
  EXPECT_TRUE(largest);
}

TEST(Fuzzer, TheSameSeedGivesTheSameMessages) {
  Fuzzer a = table_fuzzer(7), b = table_fuzzer(7), c = table_fuzzer(8);
  bool differs = false;
  for (int i = 0; i < 3000; ++i) {
    const auto x = a.next(kNow + i), y = b.next(kNow + i), z = c.next(kNow + i);
    ASSERT_EQ(x.channel, y.channel);
    ASSERT_EQ(x.bytes, y.bytes) << x.what;
    differs = differs || x.bytes != z.bytes;
  }
  EXPECT_TRUE(differs);
}

/// What a receiver's decode and validate() say of each kind that must be
/// refused before the time check.
TEST(Fuzzer, EveryBrokenMessageIsRefusedByDecodeOrValidate) {
  Fuzzer fuzzer = table_fuzzer();
  for (const auto& entry : channel_table()) {
    const std::string channel = entry.prefix ? "HEARTBEAT_FUZZ" : entry.name;
    const MessageSupport& support = *find_message_support(entry.type);
    for (const auto& m : fuzzer.all_of(channel, kNow)) {
      EXPECT_EQ(m.valid, support.check(m.bytes.data(), m.bytes.size()).empty()) << m.what;
      const bool must_refuse = m.kind == Kind::kTruncated || m.kind == Kind::kWrongFingerprint ||
                               m.kind == Kind::kSizeField || m.kind == Kind::kStringLength ||
                               m.kind == Kind::kNonFinite;
      if (!must_refuse) continue;
      EXPECT_NE(support.check(m.bytes.data(), m.bytes.size()), "")
          << channel << ": accepted " << kind_name(m.kind) << ": " << m.what;
    }
  }
}

/// Every fuzz message of every channel through a Node on memq://, as a
/// service receives it: nothing throws, and only what may pass passes.
TEST(Fuzzer, ANodeRefusesEveryMessageItMustAndSurvivesTheRest) {
  lcm::LCM lcm("memq://");
  ManualClock clock(kNow);
  Node node("fuzzed", lcm, clock);
  Fuzzer fuzzer = table_fuzzer();
  std::map<std::string, int> accepted;
  std::string last;
  for (const auto& channel : fuzzer.channels()) {
    const ChannelInfo* entry = find_channel(channel);
    ASSERT_NE(entry, nullptr) << channel;
    find_message_support(entry->type)
        ->subscribe(node, channel, SubscribeOptions{1.0, 1.0},
                    [&accepted, &last, channel] { ++accepted[channel + ": " + last]; });
  }
  int64_t sent = 0;
  for (const auto& channel : fuzzer.channels()) {
    for (const auto& m : fuzzer.all_of(channel, kNow)) {
      last = std::string(kind_name(m.kind)) + ": " + m.what;
      lcm.publish(m.channel, m.bytes.data(), static_cast<unsigned>(m.bytes.size()));
      while (lcm.handleTimeout(0) > 0) {
      }
      ++sent;
      // What may pass: an extreme but finite number, an integer out of the
      // usual range, a stamp other than the message's own utime (t0_utime,
      // last_seen_utime, map_utime: the services judge those), and noise
      // that happens to land in such a place.
      const bool may_pass =
          m.kind == Kind::kExtremeNumber || m.kind == Kind::kNoise ||
          (m.kind == Kind::kStamp && m.what.find(" utime = ") == std::string::npos);
      if (!may_pass) {
        EXPECT_EQ(accepted.count(m.channel + ": " + last), 0u) << m.channel << ": " << last;
      }
    }
  }
  EXPECT_GT(sent, 3000);
  // Each message was either handed to its handler or counted as refused.
  int64_t handled = 0;
  for (const auto& [what, n] : accepted) handled += n;
  EXPECT_EQ(node.counters().received, handled);
  EXPECT_EQ(node.counters().received + node.counters().rejected, sent);
  // Counted by kind, in a bounded table, however many messages.
  EXPECT_LE(node.counters().rejected_by_reason.size(), kMaxRejectKinds + 1);
}

TEST(Fuzzer, TakesAMessageHeardOnTheBusAsItsSeedOnlyWhenValidAndNow) {
  Fuzzer fuzzer = table_fuzzer();
  const MessageSupport& nav = *find_message_support("nav_state_t");
  auto heard = nav.seed();
  // Stamped now (utime is bytes 8-15).
  for (int i = 0; i < 8; ++i) heard[8 + i] = static_cast<uint8_t>(kNow >> (56 - 8 * i));
  heard[24] ^= 0x01;  // another position: a message of its own
  EXPECT_TRUE(fuzzer.offer_seed("NAV_STATE", heard.data(), heard.size(), kNow, 5000000, 4096));
  const auto after = fuzzer.all_of("NAV_STATE", kNow);
  const auto oversized = std::find_if(
      after.begin(), after.end(), [](const FuzzMessage& m) { return m.kind == Kind::kOversized; });
  ASSERT_NE(oversized, after.end());
  EXPECT_EQ(oversized->bytes[24], heard[24]);
  // Not one stamped far from now, not an invalid one, not one too large.
  EXPECT_FALSE(
      fuzzer.offer_seed("NAV_STATE", heard.data(), heard.size(), kNow + 60000000, 5000000, 4096));
  // A quiet NaN (big-endian 7f f8 00..) in the first double after the stamp.
  auto nan = heard;
  ASSERT_GE(nan.size(), 32u);
  const uint8_t quiet_nan[8] = {0x7f, 0xf8, 0, 0, 0, 0, 0, 0};
  std::memcpy(nan.data() + 24, quiet_nan, sizeof(quiet_nan));
  EXPECT_FALSE(fuzzer.offer_seed("NAV_STATE", nan.data(), nan.size(), kNow, 5000000, 4096));
  EXPECT_FALSE(fuzzer.offer_seed("NAV_STATE", heard.data(), heard.size(), kNow, 5000000, 64));
  EXPECT_FALSE(fuzzer.offer_seed("NOT_FUZZED", heard.data(), heard.size(), kNow, 5000000, 4096));
}

}  // namespace
}  // namespace ofn::fuzz
