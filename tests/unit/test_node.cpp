// Node: checked subscriptions, clock-driven timers and heartbeats, on an
// in-process LCM with a manual clock.

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <limits>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/node.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/nav_state_t.hpp"

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
    node.fire_due_timers(t);
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

TEST_F(NodeTest, TimerCatchesUpThenSkipsAheadWhenFarBehind) {
  clock_.set(0);
  Node node("timers", lcm_, clock_);
  int fired = 0;
  node.add_timer(
      0.01, [&] { ++fired; }, "10ms");
  node.fire_due_timers(0);
  EXPECT_EQ(fired, 1);
  // 50 ms late: the missed periods are run.
  clock_.set(50000);
  node.fire_due_timers(50000);
  EXPECT_EQ(fired, 6);
  // 10 s late with a catch-up bound of 5: five runs, then it skips ahead.
  clock_.set(50000 + 10 * kMicrosPerSecond);
  node.fire_due_timers(clock_.now(), 5);
  EXPECT_EQ(fired, 11);
  EXPECT_GT(node.next_deadline(), clock_.now());
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
    node.fire_due_timers(t);
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
  node.fire_due_timers(0);
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

}  // namespace
}  // namespace ofn
