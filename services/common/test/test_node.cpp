// Node: checked subscriptions, clock-driven timers and heartbeats, on an
// in-process LCM with a manual clock.

#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/message_caps.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/scan_world_t.hpp"

namespace ofn {
namespace {

const char* kChannel = "TEST_NAV";

nav_state_t nav_at(Utime t) {
  nav_state_t m{};
  m.utime = t;
  m.frame = "NED";
  m.position[2] = -30;
  m.quaternion[0] = 1.0;
  return m;
}

class NodeTest : public ::testing::Test {
 protected:
  NodeTest() : lcm_("memq://"), clock_(10 * kMicrosPerSecond) {}

  void deliver() {
    while (lcm_.handleTimeout(0) > 0) {
    }
  }

  /// A node "x" whose TEST_NAV handler counts calls.
  Node& subscribed(SubscribeOptions options = {}) {
    node_ = std::make_unique<Node>("x", lcm_, clock_);
    node_->subscribe<nav_state_t>(
        kChannel, [this](const nav_state_t& m) { handled_.push_back(m); }, options);
    return *node_;
  }

  lcm::LCM lcm_;
  ManualClock clock_;
  std::unique_ptr<Node> node_;
  std::vector<nav_state_t> handled_;
};

TEST_F(NodeTest, ValidMessageReachesTheHandler) {
  ASSERT_TRUE(lcm_.good());
  Node& node = subscribed();
  const nav_state_t sent = nav_at(clock_.now());
  node.publish(kChannel, sent);
  deliver();
  ASSERT_EQ(handled_.size(), 1u);
  EXPECT_EQ(handled_[0].utime, sent.utime);
  EXPECT_DOUBLE_EQ(handled_[0].position[2], -30.0);
  EXPECT_EQ(node.counters().received, 1);
  EXPECT_EQ(node.counters().rejected, 0);
  EXPECT_EQ(node.counters().late, 0);
}

TEST_F(NodeTest, GarbageBytesAreRejectedAndNeverHandled) {
  Node& node = subscribed();
  const unsigned char garbage[] = {0xde, 0xad, 0xbe, 0xef, 0x00, 0x01, 0x02, 0x03,
                                   0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a};
  lcm_.publish(kChannel, garbage, sizeof garbage);
  lcm_.publish(kChannel, garbage, 3);  // too short even for the type hash
  deliver();
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 2);
  EXPECT_EQ(node.counters().received, 0);
  EXPECT_NE(node.counters().last_reject_reason.find(kChannel), std::string::npos)
      << node.counters().last_reject_reason;
  // A good message afterwards still gets through.
  node.publish(kChannel, nav_at(clock_.now()));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
  EXPECT_EQ(node.counters().received, 1);
}

TEST_F(NodeTest, TruncatedMessageIsRejected) {
  Node& node = subscribed();
  const nav_state_t m = nav_at(clock_.now());
  std::vector<uint8_t> buf(m.getEncodedSize());
  ASSERT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  lcm_.publish(kChannel, buf.data(), static_cast<unsigned int>(buf.size() - 8));
  // And one with trailing bytes.
  buf.resize(buf.size() + 8 + 8, 0);
  lcm_.publish(kChannel, buf.data(), static_cast<unsigned int>(buf.size()));
  deliver();
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 2);
}

TEST_F(NodeTest, NaNFilledNavStateIsRejected) {
  Node& node = subscribed();
  nav_state_t m = nav_at(clock_.now());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 3; ++i) m.position[i] = m.velocity[i] = m.euler[i] = m.body_rates[i] = nan;
  for (double& q : m.quaternion) q = nan;
  node.publish(kChannel, m);
  deliver();
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_EQ(node.counters().received, 0);
  EXPECT_EQ(node.counters().rejected_by_reason.size(), 1u);
}

TEST_F(NodeTest, StaleMessageIsRejectedAndCountedLate) {
  SubscribeOptions options;
  options.max_age = 0.2;
  Node& node = subscribed(options);
  node.publish(kChannel, nav_at(clock_.now() - to_utime(0.5)));
  deliver();
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_EQ(node.counters().late, 1);
  // Within the bound it is accepted.
  node.publish(kChannel, nav_at(clock_.now() - to_utime(0.1)));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
  EXPECT_EQ(node.counters().late, 1);
}

TEST_F(NodeTest, TheFarthestStampsEitherWayAreRejected) {
  // -2^63 is as stale as a stamp can be; `now - stamp` overflowed for it,
  // and it passed as fresh (found by the bus fuzz).
  SubscribeOptions options;
  options.max_age = 0.2;
  Node& node = subscribed(options);
  for (Utime stamp : {INT64_MIN, INT64_MIN + 1, Utime{-1}, INT64_MAX}) {
    node.publish(kChannel, nav_at(stamp));
    deliver();
  }
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 4);
  EXPECT_EQ(node.counters().late, 3);
  EXPECT_NE(node.counters().last_reject_reason.find("in the future"), std::string::npos);
}

TEST_F(NodeTest, WithoutMaxAgeOldMessagesAreAccepted) {
  Node& node = subscribed();  // max_age 0: no staleness check
  node.publish(kChannel, nav_at(0));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
  EXPECT_EQ(node.counters().late, 0);
}

TEST_F(NodeTest, MessageFromTheFutureIsRejected) {
  SubscribeOptions options;
  options.max_future = 1.0;
  Node& node = subscribed(options);
  node.publish(kChannel, nav_at(clock_.now() + to_utime(2.0)));
  deliver();
  EXPECT_TRUE(handled_.empty());
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_EQ(node.counters().late, 0);
  // Slightly ahead (clock skew) is tolerated.
  node.publish(kChannel, nav_at(clock_.now() + to_utime(0.5)));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
}

TEST_F(NodeTest, TimerFiresOncePerPeriodOfClockTime) {
  clock_.set(0);
  Node node("timers", lcm_, clock_);
  std::vector<Utime> fired;
  node.add_timer(
      0.01, [&] { fired.push_back(clock_.now()); }, "10ms");
  for (Utime t = 1000; t <= kMicrosPerSecond; t += 1000) {
    clock_.set(t);
    node.fire_due_timers();
  }
  EXPECT_EQ(fired.size(), 100u);
  // On whole multiples of the period, 10 ms apart.
  for (size_t i = 0; i < fired.size(); ++i) {
    EXPECT_EQ(fired[i] % 10000, 0) << i;
    if (i > 0) {
      EXPECT_EQ(fired[i] - fired[i - 1], 10000) << i;
    }
  }
  EXPECT_GT(node.next_deadline(), kMicrosPerSecond);
  deliver();
}

TEST_F(NodeTest, ALateTimerFiresOnceAndKeepsToItsPeriod) {
  clock_.set(0);
  Node node("timers", lcm_, clock_);
  std::vector<Utime> fired;
  node.add_timer(
      0.01, [&] { fired.push_back(clock_.now()); }, "10ms");
  node.fire_due_timers();
  EXPECT_EQ(fired.size(), 1u);
  // 45 ms late (a starved process): once, not the four periods it missed.
  clock_.set(55000);
  node.fire_due_timers();
  EXPECT_EQ(fired.size(), 2u);
  // Then on its period again, at the next whole multiple.
  EXPECT_EQ(node.next_deadline(), 60000);
  clock_.set(60000);
  node.fire_due_timers();
  EXPECT_EQ(fired.size(), 3u);
  EXPECT_EQ(fired.back(), 60000);
  deliver();
}

TEST_F(NodeTest, AClockJumpAheadFiresATimerOnceNotABurst) {
  clock_.set(0);
  Node node("timers", lcm_, clock_);
  std::vector<Utime> fired;
  node.add_timer(
      0.01, [&] { fired.push_back(clock_.now()); }, "10ms");
  node.fire_due_timers();
  // 1,000 s ahead: 100,000 periods missed; one callback.
  const Utime jumped = 1000 * kMicrosPerSecond + 3000;
  clock_.set(jumped);
  node.fire_due_timers();
  ASSERT_EQ(fired.size(), 2u);
  EXPECT_EQ(fired[1], jumped);
  // No silence after it: every 10 ms from the next multiple on.
  for (Utime t = jumped; t <= jumped + 100000; t += 1000) {
    clock_.set(t);
    node.fire_due_timers();
  }
  ASSERT_EQ(fired.size(), 12u);
  for (size_t i = 3; i < fired.size(); ++i) EXPECT_EQ(fired[i] - fired[i - 1], 10000) << i;
  EXPECT_EQ(fired[2], 1000 * kMicrosPerSecond + 10000);
  deliver();
}

TEST_F(NodeTest, AClockThatGoesBackDoesNotSilenceATimer) {
  clock_.set(1000 * kMicrosPerSecond);
  Node node("timers", lcm_, clock_);
  std::vector<Utime> fired;
  node.add_timer(
      0.01, [&] { fired.push_back(clock_.now()); }, "10ms");
  node.fire_due_timers();
  ASSERT_EQ(fired.size(), 1u);
  // 1,000 s back: the old deadline is 1,000 s away; the timer starts on its
  // period afresh instead of waiting for it.
  for (Utime t = 5000; t <= 105000; t += 1000) {
    clock_.set(t);
    node.fire_due_timers();
  }
  ASSERT_EQ(fired.size(), 11u);
  EXPECT_EQ(fired[1], 10000);
  for (size_t i = 2; i < fired.size(); ++i) EXPECT_EQ(fired[i] - fired[i - 1], 10000) << i;
  deliver();
}

TEST_F(NodeTest, TimerPeriodMustBePositive) {
  Node node("timers", lcm_, clock_);
  EXPECT_THROW(node.add_timer(
                   0.0, [] {}, "zero"),
               std::invalid_argument);
  EXPECT_THROW(node.add_timer(
                   -1.0, [] {}, "negative"),
               std::invalid_argument);
}

TEST_F(NodeTest, HeartbeatReportsServiceAndCounters) {
  clock_.set(0);
  Node& node = subscribed();
  // One rejected and one accepted message before the heartbeat.
  const unsigned char garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  lcm_.publish(kChannel, garbage, sizeof garbage);
  node.publish(kChannel, nav_at(0));
  deliver();

  Node monitor("monitor", lcm_, clock_);
  std::vector<heartbeat_t> beats;
  monitor.subscribe<heartbeat_t>(heartbeat_channel("x"),
                                 [&](const heartbeat_t& h) { beats.push_back(h); });
  EXPECT_EQ(heartbeat_channel("x"), "HEARTBEAT_X");

  for (Utime t = 0; t <= 2 * kMicrosPerSecond; t += 10000) {
    clock_.set(t);
    node.fire_due_timers();
    deliver();
  }
  ASSERT_EQ(beats.size(), 3u);  // one a second: at 0, 1 and 2 s
  const heartbeat_t& hb = beats.back();
  EXPECT_EQ(hb.service, "x");
  EXPECT_EQ(hb.rejected, 1);
  EXPECT_EQ(hb.received, 1);
  EXPECT_EQ(hb.late, 0);
  EXPECT_NE(hb.last_reject_reason.find(kChannel), std::string::npos) << hb.last_reject_reason;
  EXPECT_EQ(hb.utime, 2 * kMicrosPerSecond);
  EXPECT_NEAR(hb.uptime, 2.0, 1e-9);
  EXPECT_EQ(hb.state, "starting");
  EXPECT_GT(hb.pid, 0);
}

TEST_F(NodeTest, HeartbeatCarriesTheState) {
  clock_.set(0);
  Node node("svc", lcm_, clock_);
  node.set_state("degraded");
  std::vector<heartbeat_t> beats;
  Node monitor("monitor", lcm_, clock_);
  monitor.subscribe<heartbeat_t>(heartbeat_channel("svc"),
                                 [&](const heartbeat_t& h) { beats.push_back(h); });
  node.fire_due_timers();
  deliver();
  ASSERT_EQ(beats.size(), 1u);
  EXPECT_EQ(beats[0].state, "degraded");
  EXPECT_EQ(beats[0].service, "svc");
}

TEST_F(NodeTest, DestroyedNodeNoLongerReceives) {
  subscribed();
  node_.reset();
  lcm::LCM& lcm = lcm_;
  const nav_state_t m = nav_at(clock_.now());
  lcm.publish(kChannel, &m);
  deliver();
  EXPECT_TRUE(handled_.empty());
}

TEST_F(NodeTest, ExplicitRejectIsCounted) {
  Node node("svc", lcm_, clock_);
  node.reject("control", "non-finite");
  node.reject("control", "non-finite");
  EXPECT_EQ(node.counters().rejected, 2);
  EXPECT_EQ(node.counters().last_reject_reason, "control: non-finite");
  EXPECT_EQ(node.counters().rejected_by_reason.at("control: non-finite"), 2);
}

TEST_F(NodeTest, AFloodOfDistinctStaleStampsIsCountedUnderOneKind) {
  // Every stale stamp gives a different reason text; counted by text, 60,000
  // of them grew a service's memory for good.
  SubscribeOptions options;
  options.max_age = 0.2;
  Node& node = subscribed(options);
  for (int i = 0; i < 2000; ++i)
    node.publish(kChannel, nav_at(clock_.now() - to_utime(1.0 + 0.001 * i)));
  deliver();
  EXPECT_EQ(node.counters().rejected, 2000);
  ASSERT_EQ(node.counters().rejected_by_reason.size(), 1u);
  EXPECT_EQ(node.counters().rejected_by_reason.begin()->first, "TEST_NAV: stale by # s");
  EXPECT_EQ(node.counters().rejected_by_reason.begin()->second, 2000);
  // The last reason keeps its numbers.
  EXPECT_NE(node.counters().last_reject_reason.find("stale by 2.999"), std::string::npos)
      << node.counters().last_reject_reason;
}

TEST_F(NodeTest, DistinctRejectKindsAreBounded) {
  Node node("svc", lcm_, clock_);
  for (int i = 0; i < 200; ++i)
    node.reject("control", "kind " + std::string(1, 'a' + i % 26) + std::string(1, 'a' + i / 26));
  EXPECT_EQ(node.counters().rejected_by_reason.size(), kMaxRejectKinds + 1);
  EXPECT_EQ(node.counters().rejected_by_reason.at(kOtherRejectKind), 200 - 64);
}

TEST(RejectKind, NumbersBecomeOneMarkWordsStay) {
  EXPECT_EQ(reject_kind("stale by 0.73 s"), "stale by # s");
  EXPECT_EQ(reject_kind("speed -1.5e+03 against 10"), "speed # against #");
  EXPECT_EQ(reject_kind("frame 'ENU' is not NED"), "frame 'ENU' is not NED");
  EXPECT_EQ(reject_kind("see - here"), "see - here");
}

/// `bytes` with the big-endian int32 at `at` replaced by `value`.
std::vector<uint8_t> with_int32(std::vector<uint8_t> bytes, size_t at, int32_t value) {
  const auto u = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<uint8_t>(u >> (24 - 8 * i));
  return bytes;
}

template <class Msg>
std::vector<uint8_t> encoded(const Msg& m) {
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  return bytes;
}

/// Where `pattern` starts in `bytes` (it must be there).
size_t find(const std::vector<uint8_t>& bytes, const std::vector<uint8_t>& pattern) {
  const auto it = std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end());
  EXPECT_NE(it, bytes.end());
  return static_cast<size_t>(it - bytes.begin());
}

// A message with a valid fingerprint and a hostile array count or string
// length: the decoders generated by lcm-gen 1.3.1 resized to it (a negative
// count threw out of the callback and aborted every subscriber; 2^26
// allocated hundreds of MB). HardenLcmDecode.cmake bounds them by the bytes
// left, so decode fails cleanly and the node rejects the message.
TEST(HostileMessage, ACountOrLengthBeyondTheBytesLeftFailsTheDecodeWithoutThrowing) {
  scan_world_t scan{};
  scan.frame = "NED";
  scan.num_points = 2;
  scan.points = {{12345.5f, 0, 0}, {1, 2, 3}};
  const std::vector<uint8_t> good = encoded(scan);
  // num_points sits just before the first point's first coordinate.
  std::vector<uint8_t> marker = with_int32({0, 0, 0, 0}, 0, 2);
  const std::vector<uint8_t> first = encoded(scan);
  float x = 12345.5f;
  uint32_t bits;
  std::memcpy(&bits, &x, 4);
  for (int i = 0; i < 4; ++i) marker.push_back(static_cast<uint8_t>(bits >> (24 - 8 * i)));
  const size_t count_at = find(first, marker);
  const size_t frame_len_at = find(good, {'N', 'E', 'D', 0}) - 4;
  scan_world_t out;
  ASSERT_EQ(out.decode(good.data(), 0, static_cast<int>(good.size())),
            static_cast<int>(good.size()));
  for (const int32_t count : {-1, -2147483647 - 1, 3, 1 << 26, 2147483647}) {
    const auto bad = with_int32(good, count_at, count);
    int decoded = 0;
    EXPECT_NO_THROW(decoded = out.decode(bad.data(), 0, static_cast<int>(bad.size())));
    EXPECT_LT(decoded, 0) << "count " << count;
  }
  for (const int32_t length : {-5, 0, 1 << 26, 2147483647}) {
    const auto bad = with_int32(good, frame_len_at, length);
    int decoded = 0;
    EXPECT_NO_THROW(decoded = out.decode(bad.data(), 0, static_cast<int>(bad.size())));
    EXPECT_LT(decoded, 0) << "length " << length;
  }
}

TEST_F(NodeTest, AHostileStringLengthIsRejectedAndTheNodeKeepsRunning) {
  Node& node = subscribed();
  const std::vector<uint8_t> good = encoded(nav_at(clock_.now()));
  const size_t frame_len_at = find(good, {'N', 'E', 'D', 0}) - 4;
  for (const int32_t length : {-1, 0, 1 << 26}) {
    const auto bad = with_int32(good, frame_len_at, length);
    lcm_.publish(kChannel, bad.data(), static_cast<unsigned>(bad.size()));
  }
  lcm_.publish(kChannel, good.data(), static_cast<unsigned>(good.size()));
  deliver();
  EXPECT_EQ(node.counters().rejected, 3);
  ASSERT_EQ(handled_.size(), 1u);  // the good one, after the three bad ones
  EXPECT_EQ(handled_[0].frame, "NED");
}

// What a publishing node sends, raw: its messages on channel "OUT", kept
// so that a test can pass them on to TEST_NAV dropped, doubled or in
// another order, as a bad link would.
class Relay {
 public:
  explicit Relay(lcm::LCM& lcm) : lcm_(lcm) {
    sub_ = lcm_.subscribeFunction(
        "OUT",
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, Relay* self) {
          const auto* data = static_cast<const uint8_t*>(rbuf->data);
          self->sent.emplace_back(data, data + rbuf->data_size);
        },
        this);
  }
  ~Relay() { lcm_.unsubscribe(sub_); }
  /// Passes message `i` (0-based, in the order sent) on to TEST_NAV.
  void pass(size_t i) const {
    lcm_.publish(kChannel, sent.at(i).data(), static_cast<unsigned>(sent.at(i).size()));
  }
  std::vector<std::vector<uint8_t>> sent;

 private:
  lcm::LCM& lcm_;
  lcm::Subscription* sub_ = nullptr;
};

TEST_F(NodeTest, EveryPublishedMessageCarriesItsNodesNumberForTheChannel) {
  Relay relay(lcm_);
  std::vector<std::vector<uint8_t>> other;
  auto* sub = lcm_.subscribeFunction(
      "OTHER",
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&,
          std::vector<std::vector<uint8_t>>* out) {
        const auto* data = static_cast<const uint8_t*>(rbuf->data);
        out->emplace_back(data, data + rbuf->data_size);
      },
      &other);
  Node node("pub", lcm_, clock_);
  const nav_state_t m = nav_at(clock_.now());
  for (int i = 0; i < 3; ++i) node.publish("OUT", m);
  node.publish("OTHER", m);
  deliver();
  lcm_.unsubscribe(sub);
  ASSERT_EQ(relay.sent.size(), 3u);
  ASSERT_EQ(other.size(), 1u);
  for (size_t i = 0; i < 3; ++i) {
    const auto& bytes = relay.sent[i];
    ASSERT_EQ(bytes.size(), m.getEncodedSize() + bus_auth::kSequenceTrailerBytes);
    ASSERT_TRUE(bus_auth::ends_with_sequence_trailer(bytes.data(), bytes.size()));
    const auto stamp = bus_auth::read_sequence_trailer(bytes.data(), bytes.size());
    EXPECT_EQ(stamp.publisher, node.publisher_id());
    EXPECT_EQ(stamp.sequence, i + 1);
    // LCM's own decoder (lcm-spy's, the Python types') stops at the
    // message's end.
    nav_state_t decoded{};
    EXPECT_EQ(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), m.getEncodedSize());
  }
  // Each channel counts from 1.
  EXPECT_EQ(bus_auth::read_sequence_trailer(other[0].data(), other[0].size()).sequence, 1u);
  EXPECT_NE(node.publisher_id(), 0u);
  // Another node, even of the same name, is another publisher.
  EXPECT_NE(Node("pub", lcm_, clock_).publisher_id(), node.publisher_id());
}

TEST_F(NodeTest, ADroppedMessageIsCountedAsOneLost) {
  Relay relay(lcm_);
  Node& node = subscribed();
  Node publisher("pub", lcm_, clock_);
  for (int i = 0; i < 5; ++i) publisher.publish("OUT", nav_at(clock_.now()));
  deliver();
  for (size_t i : {0, 1, 3, 4}) relay.pass(i);  // the third never arrives
  deliver();
  EXPECT_EQ(handled_.size(), 4u);
  const SequenceCounts c = node.input_counts().at(kChannel);
  EXPECT_EQ(c.received, 4);
  EXPECT_EQ(c.lost, 1);
  EXPECT_EQ(c.duplicated, 0);
  EXPECT_EQ(c.unsequenced, 0);
  EXPECT_EQ(c.publishers, 1);
}

TEST_F(NodeTest, ADuplicateIsCountedAndAnOvertakenMessageIsNotLost) {
  Relay relay(lcm_);
  Node& node = subscribed();
  Node publisher("pub", lcm_, clock_);
  for (int i = 0; i < 4; ++i) publisher.publish("OUT", nav_at(clock_.now()));
  deliver();
  // 1, 1 again, 3 before 2, 4.
  for (size_t i : {0, 0, 2, 1, 3}) relay.pass(i);
  deliver();
  const SequenceCounts c = node.input_counts().at(kChannel);
  EXPECT_EQ(c.received, 5);
  EXPECT_EQ(c.duplicated, 2);  // the copy, and 2 behind 3
  EXPECT_EQ(c.lost, 0);
  // Counted, not dropped: the handler sees what the bus delivered.
  EXPECT_EQ(handled_.size(), 5u);
}

TEST_F(NodeTest, ARestartedPublisherIsANewOneNotLoss) {
  Relay relay(lcm_);
  Node& node = subscribed();
  {
    Node first("pub", lcm_, clock_);
    for (int i = 0; i < 3; ++i) first.publish("OUT", nav_at(clock_.now()));
    deliver();
  }
  clock_.set(clock_.now() + kMicrosPerSecond);
  Node again("pub", lcm_, clock_);
  for (int i = 0; i < 2; ++i) again.publish("OUT", nav_at(clock_.now()));
  deliver();
  ASSERT_EQ(relay.sent.size(), 5u);
  for (size_t i = 0; i < 5; ++i) relay.pass(i);
  deliver();
  const SequenceCounts c = node.input_counts().at(kChannel);
  EXPECT_EQ(c.received, 5);
  EXPECT_EQ(c.lost, 0);
  EXPECT_EQ(c.duplicated, 0);
  EXPECT_EQ(c.publishers, 2);
}

TEST_F(NodeTest, AnUnsequencedMessageIsAcceptedAndCountedAsSuch) {
  // An older recording, or a publisher that is not a Node: no trailer.
  Node& node = subscribed();
  const auto bytes = encoded(nav_at(clock_.now()));
  lcm_.publish(kChannel, bytes.data(), static_cast<unsigned>(bytes.size()));
  node.publish(kChannel, nav_at(clock_.now()));
  deliver();
  EXPECT_EQ(handled_.size(), 2u);
  EXPECT_EQ(node.counters().rejected, 0);
  const SequenceCounts c = node.input_counts().at(kChannel);
  EXPECT_EQ(c.received, 2);
  EXPECT_EQ(c.unsequenced, 1);
  EXPECT_EQ(c.lost, 0);
  EXPECT_EQ(c.publishers, 1);
}

TEST_F(NodeTest, AMessageThatFailsValidationStillCountsForItsNumber) {
  // Rejected for its content, not lost: the next one is no gap.
  Relay relay(lcm_);
  Node& node = subscribed();
  Node publisher("pub", lcm_, clock_);
  nav_state_t bad = nav_at(clock_.now());
  bad.position[0] = std::numeric_limits<double>::quiet_NaN();
  publisher.publish("OUT", nav_at(clock_.now()));
  publisher.publish("OUT", bad);
  publisher.publish("OUT", nav_at(clock_.now()));
  deliver();
  for (size_t i = 0; i < 3; ++i) relay.pass(i);
  deliver();
  EXPECT_EQ(handled_.size(), 2u);
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_EQ(node.input_counts().at(kChannel).received, 3);
  EXPECT_EQ(node.input_counts().at(kChannel).lost, 0);
}

TEST_F(NodeTest, TheHeartbeatReportsEachInputsCounts) {
  clock_.set(0);
  Relay relay(lcm_);
  Node& node = subscribed();
  node.subscribe<global_path_t>(channels::kGlobalPath, [](const global_path_t&) {});
  Node publisher("pub", lcm_, clock_);
  for (int i = 0; i < 4; ++i) publisher.publish("OUT", nav_at(0));
  deliver();
  for (size_t i : {0, 2, 3, 3}) relay.pass(i);
  deliver();
  Node monitor("monitor", lcm_, clock_);
  std::vector<heartbeat_t> beats;
  monitor.subscribe<heartbeat_t>(heartbeat_channel("x"),
                                 [&](const heartbeat_t& h) { beats.push_back(h); });
  node.fire_due_timers();
  deliver();
  ASSERT_EQ(beats.size(), 1u);
  const heartbeat_t& hb = beats[0];
  ASSERT_EQ(hb.num_inputs, 2);
  // By channel name.
  EXPECT_EQ(hb.inputs[0].channel, channels::kGlobalPath);
  EXPECT_EQ(hb.inputs[0].received, 0);
  EXPECT_EQ(hb.inputs[1].channel, kChannel);
  EXPECT_EQ(hb.inputs[1].received, 4);
  EXPECT_EQ(hb.inputs[1].lost, 1);
  EXPECT_EQ(hb.inputs[1].duplicated, 1);
  EXPECT_EQ(hb.inputs[1].unsequenced, 0);
  EXPECT_EQ(hb.inputs[1].publishers, 1);
  // The monitor counts the heartbeat channel like any input.
  EXPECT_EQ(monitor.input_counts().at(heartbeat_channel("x")).received, 1);
}

TEST_F(NodeTest, ASecondSubscriptionToAChannelDoesNotCountItsMessagesTwice) {
  Node& node = subscribed();
  int second = 0;
  node.subscribe<nav_state_t>(kChannel, [&](const nav_state_t&) { ++second; });
  node.publish(kChannel, nav_at(clock_.now()));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
  EXPECT_EQ(second, 1);
  EXPECT_EQ(node.input_counts().at(kChannel).received, 1);
  EXPECT_EQ(node.input_counts().at(kChannel).duplicated, 0);
}

}  // namespace
}  // namespace ofn

namespace ofn {
namespace {

// The authenticated bus through a Node: roles "a" (this process) and "b"
// (another host) under one policy, on one memq:// handle.
class AuthenticatedNodeTest : public NodeTest {
 protected:
  AuthenticatedNodeTest() {
    const auto policy = bus_auth::PublishPolicy::parse(
        "publishers:\n  a: [HEARTBEAT_X, OWN]\n  b: [TEST_NAV]\n", "test policy");
    for (const char* role : {"a", "b"}) pairs_[role] = bus_auth::generate_key_pair();
    std::map<std::string, bus_auth::PublicKey> keys;
    for (const auto& [role, pair] : pairs_) keys[role] = pair.public_key;
    const auto wall = [this] { return wall_now_; };
    own_ =
        std::make_shared<bus_auth::Authenticator>("a", pairs_["a"].secret_key, keys, policy, wall);
    other_ =
        std::make_unique<bus_auth::Authenticator>("b", pairs_["b"].secret_key, keys, policy, wall);
    attach_authenticator(lcm_, own_);
  }
  ~AuthenticatedNodeTest() override {
    node_.reset();
    detach_authenticator(lcm_);
  }

  /// `m` encoded, sealed by role b for `channel`, published raw.
  void send_from_b(const std::string& channel, const nav_state_t& m, bool seal = true) {
    std::vector<uint8_t> bytes(m.getEncodedSize());
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    if (seal) other_->seal(channel, bytes);
    lcm_.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    deliver();
  }

  int64_t wall_now_ = 1'800'000'000'000'000;
  std::map<std::string, bus_auth::KeyPair> pairs_;
  std::shared_ptr<bus_auth::Authenticator> own_;
  std::unique_ptr<bus_auth::Authenticator> other_;
};

TEST_F(AuthenticatedNodeTest, SignedMessagesPassAndForgeriesAreCountedNotHandled) {
  Node& node = subscribed();
  ASSERT_TRUE(node.authenticated());
  send_from_b(kChannel, nav_at(clock_.now()));
  ASSERT_EQ(handled_.size(), 1u);
  EXPECT_EQ(node.counters().received, 1);

  // Unsigned (a stranger with LCM and the types): refused.
  send_from_b(kChannel, nav_at(clock_.now()), false);
  // A replay of a signed message.
  std::vector<uint8_t> bytes(nav_at(clock_.now()).getEncodedSize());
  nav_at(clock_.now()).encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  other_->seal(kChannel, bytes);
  lcm_.publish(kChannel, bytes.data(), static_cast<unsigned int>(bytes.size()));
  lcm_.publish(kChannel, bytes.data(), static_cast<unsigned int>(bytes.size()));
  deliver();
  EXPECT_EQ(handled_.size(), 2u);
  EXPECT_EQ(node.counters().unauthenticated, 2);
  EXPECT_EQ(node.counters().rejected, 2);
  EXPECT_EQ(node.counters().rejected_by_reason.count("TEST_NAV: unauthenticated: not signed"), 1u);
}

TEST_F(AuthenticatedNodeTest, PublishedMessagesAreSignedAndDecodableByLcmsOwnDecoder) {
  Node& node = subscribed();
  std::vector<std::vector<uint8_t>> raw;
  auto* sub = lcm_.subscribeFunction(
      "OWN",
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&,
          std::vector<std::vector<uint8_t>>* out) {
        const auto* data = static_cast<const uint8_t*>(rbuf->data);
        out->emplace_back(data, data + rbuf->data_size);
      },
      &raw);
  const auto sent = nav_at(clock_.now());
  node.publish("OWN", sent);
  deliver();
  lcm_.unsubscribe(sub);
  ASSERT_EQ(raw.size(), 1u);
  const auto& bytes = raw.front();
  EXPECT_EQ(bytes.size(), static_cast<size_t>(sent.getEncodedSize()) + bus_auth::kMaxTrailerBytes);
  // LCM's decoder reads the message from the front and stops at its end,
  // which is what lcm-spy does with the trailer.
  nav_state_t decoded{};
  EXPECT_EQ(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), sent.getEncodedSize());
  EXPECT_EQ(decoded.utime, sent.utime);
  // Another host's authenticator accepts it as role a's.
  const auto opened = other_->open("OWN", bytes.data(), bytes.size());
  EXPECT_TRUE(opened.authentic) << opened.reason;
  EXPECT_EQ(opened.role, "a");
}

TEST_F(AuthenticatedNodeTest, TheSequenceIsSignedAndCountedOnTheAuthenticatedBus) {
  Node& node = subscribed();
  // What this node (role a) publishes, as another host receives it.
  std::vector<std::vector<uint8_t>> raw;
  auto* sub = lcm_.subscribeFunction(
      "OWN",
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&,
          std::vector<std::vector<uint8_t>>* out) {
        const auto* data = static_cast<const uint8_t*>(rbuf->data);
        out->emplace_back(data, data + rbuf->data_size);
      },
      &raw);
  node.publish("OWN", nav_at(clock_.now()));
  deliver();
  lcm_.unsubscribe(sub);
  ASSERT_EQ(raw.size(), 1u);
  // payload | sequence trailer | authentication trailer
  auto bytes = raw[0];
  const size_t payload = static_cast<size_t>(nav_at(0).getEncodedSize());
  ASSERT_EQ(bytes.size(), payload + bus_auth::kMaxTrailerBytes);
  const size_t before_signature = bytes.size() - bus_auth::kTrailerBytes;
  ASSERT_TRUE(bus_auth::ends_with_sequence_trailer(bytes.data(), before_signature));
  EXPECT_EQ(bus_auth::read_sequence_trailer(bytes.data(), before_signature).sequence, 1u);
  // A renumbered message (the sequence's last byte) fails the signature;
  // the message as sent passes.
  auto renumbered = bytes;
  renumbered[before_signature - bus_auth::kSequenceTrailerMagic.size() - 1] ^= 0x01;
  const auto opened = other_->open("OWN", renumbered.data(), renumbered.size());
  EXPECT_FALSE(opened.authentic);
  EXPECT_NE(opened.reason.find("bad signature"), std::string::npos) << opened.reason;
  EXPECT_TRUE(other_->open("OWN", bytes.data(), bytes.size()).authentic);

  // Role b's numbered messages reach this node: 1, 2, then 4.
  auto numbered = [&](uint64_t sequence) {
    std::vector<uint8_t> m = encoded(nav_at(clock_.now()));
    bus_auth::append_sequence_trailer(m, {77, sequence});
    wall_now_ += 10;
    other_->seal(kChannel, m);
    lcm_.publish(kChannel, m.data(), static_cast<unsigned>(m.size()));
    deliver();
  };
  for (uint64_t sequence : {1, 2, 4}) numbered(sequence);
  EXPECT_EQ(handled_.size(), 3u);
  const SequenceCounts c = node.input_counts().at(kChannel);
  EXPECT_EQ(c.received, 3);
  EXPECT_EQ(c.lost, 1);
  EXPECT_EQ(c.unsequenced, 0);
}

TEST_F(AuthenticatedNodeTest, APolicyWithoutTheServiceHeartbeatIsAnErrorAtStart) {
  EXPECT_THROW(Node("y", lcm_, clock_), bus_auth::KeyError);
}

TEST_F(NodeTest, WithoutAuthenticationATrailerIsIgnoredAndOtherTailsAreNot) {
  // A replayed log of an authenticated flight reaches an open bus: the
  // messages decode; bytes after a message that are not a trailer do not.
  Node& node = subscribed();
  const auto m = nav_at(clock_.now());
  std::vector<uint8_t> bytes(m.getEncodedSize());
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  auto signed_bytes = bytes;
  signed_bytes.resize(bytes.size() + bus_auth::kTrailerBytes, 0);
  std::memcpy(signed_bytes.data() + signed_bytes.size() - 4, bus_auth::kTrailerMagic.data(), 4);
  lcm_.publish(kChannel, signed_bytes.data(), static_cast<unsigned int>(signed_bytes.size()));
  auto tail = bytes;
  tail.push_back(0);
  lcm_.publish(kChannel, tail.data(), static_cast<unsigned int>(tail.size()));
  deliver();
  EXPECT_EQ(handled_.size(), 1u);
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_FALSE(node.authenticated());
}

global_path_t path_of(int points, Utime t) {
  global_path_t m{};
  m.utime = t;
  m.frame = "NED";
  m.status = global_path_t::OK;
  m.num_points = points;
  for (int i = 0; i < points; ++i) m.points.push_back({1.0 * i, 0.0, -30.0});
  return m;
}

TEST_F(NodeTest, AMessageOverItsChannelsCapIsRejectedBeforeDecodingAndANormalOnePasses) {
  Node node("planner_reader", lcm_, clock_);
  std::vector<int32_t> got;
  node.subscribe<global_path_t>(channels::kGlobalPath,
                                [&](const global_path_t& m) { got.push_back(m.num_points); });
  // 3,000 points are 72 KB, a valid path (validate takes up to 10,000) but
  // over GLOBAL_PATH's 64 KiB; the shipped planner's longest was 4 KB.
  const global_path_t big = path_of(3000, clock_.now());
  ASSERT_GT(static_cast<size_t>(big.getEncodedSize()), max_message_bytes(channels::kGlobalPath));
  ASSERT_EQ(validate(big), "");
  node.publish(channels::kGlobalPath, big);
  node.publish(channels::kGlobalPath, path_of(100, clock_.now()));
  deliver();
  ASSERT_EQ(got, std::vector<int32_t>{100});
  EXPECT_EQ(node.counters().received, 1);
  EXPECT_EQ(node.counters().rejected, 1);
  EXPECT_NE(node.counters().last_reject_reason.find("GLOBAL_PATH: oversized: 72"),
            std::string::npos)
      << node.counters().last_reject_reason;
  // Counted by kind, without its numbers.
  EXPECT_EQ(node.counters().rejected_by_reason.count(
                "GLOBAL_PATH: oversized: # bytes, over the channel's cap of #"),
            1u);
}

TEST_F(NodeTest, OneByteOverTheCapAndTheTrailersRoomIsNotDecoded) {
  // Garbage of the cap's size plus both trailers' is judged by the decoder
  // (undecodable); one byte more never reaches it.
  Node& node = subscribed();
  const size_t limit = max_message_bytes(kChannel) + bus_auth::kMaxTrailerBytes;
  std::vector<uint8_t> junk(limit, 0x5a);
  lcm_.publish(kChannel, junk.data(), static_cast<unsigned>(junk.size()));
  junk.push_back(0x5a);
  lcm_.publish(kChannel, junk.data(), static_cast<unsigned>(junk.size()));
  deliver();
  EXPECT_EQ(node.counters().rejected, 2);
  EXPECT_EQ(node.counters().rejected_by_reason.count("TEST_NAV: undecodable (# bytes)"), 1u);
  EXPECT_EQ(node.counters().rejected_by_reason.count(
                "TEST_NAV: oversized: # bytes, over the channel's cap of #"),
            1u);
  EXPECT_TRUE(handled_.empty());
}

TEST(MessageCaps, EveryChannelHasOneAndHeartbeatsShareOne) {
  EXPECT_EQ(max_message_bytes(channels::kNavState), 1024u);
  EXPECT_EQ(max_message_bytes(channels::kObstacleGrid), 512u * 1024u);
  EXPECT_EQ(max_message_bytes("HEARTBEAT_MAPPER"), max_message_bytes("HEARTBEAT_CONTROLLER"));
  EXPECT_LT(max_message_bytes("HEARTBEAT_MAPPER"), max_message_bytes(channels::kLidarRaw));
  // A channel the table does not name gets the largest cap.
  EXPECT_EQ(max_message_bytes("SOMETHING_ELSE"), max_message_bytes(channels::kRefTraj));
  EXPECT_EQ(max_received_bytes(channels::kNavState), 1024u + bus_auth::kMaxTrailerBytes);
  // Every channel's cap is above its largest message in the flights the
  // table was measured on (channel_table.cpp).
  EXPECT_GT(max_message_bytes(channels::kLidarRaw), 23220u);
  EXPECT_GT(max_message_bytes(channels::kScanWorld), 16384u);
  EXPECT_GT(max_message_bytes(channels::kObstacleGrid), 55764u);
  EXPECT_GT(max_message_bytes(channels::kRefTraj), 203489u);
  EXPECT_GT(max_message_bytes(channels::kGlobalPath), 4021u);
}

}  // namespace
}  // namespace ofn
