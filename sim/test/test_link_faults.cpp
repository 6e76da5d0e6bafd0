// The lockstep runner's bad link: LCM's fragment count, the seeded draws of
// loss and delay, one fate per message and host, nothing within a host
// unless asked, and the Node hook that applies it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/sim/link_faults.hpp"

namespace ofn::sim {
namespace {

LinkFaultsConfig two_hosts(double loss, uint64_t seed = 1) {
  LinkFaultsConfig c;
  c.datagram_loss = loss;
  c.seed = seed;
  c.host_of = {{"vehicle_sim", "onboard1"},
               {"controller", "onboard1"},
               {"mapper", "onboard2"},
               {"rh_optimizer", "onboard2"}};
  return c;
}

TEST(LinkFaults, FragmentsFollowLcmsFraming) {
  EXPECT_EQ(datagrams_for(0), 1u);
  EXPECT_EQ(datagrams_for(kShortMessageMax), 1u);
  EXPECT_EQ(datagrams_for(kShortMessageMax + 1), 2u);
  EXPECT_EQ(datagrams_for(9600), 7u);    // a scan
  EXPECT_EQ(datagrams_for(13000), 10u);  // a plan
}

TEST(LinkFaults, NothingIsLostWithinAHost) {
  LinkFaults link(two_hosts(0.9));
  link.published("vehicle_sim", "NAV_STATE");
  for (int i = 0; i < 1000; ++i)
    ASSERT_TRUE(link.deliver("controller", "NAV_STATE", 20000).arrives);
  EXPECT_TRUE(link.counts().empty());
}

TEST(LinkFaults, BetweenHostsTheLossRateIsThatOfEveryFragmentArriving) {
  LinkFaults link(two_hosts(0.1, 7));
  link.published("vehicle_sim", "NAV_STATE");
  link.published("vehicle_sim", "SCAN_WORLD");
  constexpr int kDraws = 20000;
  int small = 0, large = 0;
  for (int i = 0; i < kDraws; ++i) {
    link.next_message();
    small += link.deliver("mapper", "NAV_STATE", 300).arrives ? 1 : 0;
    link.next_message();
    large += link.deliver("mapper", "SCAN_WORLD", 9600).arrives ? 1 : 0;
  }
  EXPECT_NEAR(small / double(kDraws), 0.9, 0.01);
  EXPECT_NEAR(large / double(kDraws), std::pow(0.9, 7), 0.01);  // 48 %
  EXPECT_EQ(link.counts().at("NAV_STATE").crossing, kDraws);
  EXPECT_EQ(link.counts().at("NAV_STATE").lost, kDraws - small);
  EXPECT_EQ(link.counts().at("SCAN_WORLD").lost, kDraws - large);
}

TEST(LinkFaults, TheServicesOfOneHostLoseTheSameMessages) {
  LinkFaults link(two_hosts(0.5, 11));
  link.published("vehicle_sim", "SCAN_WORLD");
  int lost = 0;
  for (int i = 0; i < 500; ++i) {
    link.next_message();
    const bool mapper = link.deliver("mapper", "SCAN_WORLD", 9600).arrives;
    ASSERT_EQ(link.deliver("rh_optimizer", "SCAN_WORLD", 9600).arrives, mapper) << i;
    lost += mapper ? 0 : 1;
  }
  EXPECT_GT(lost, 400);  // 1 - 0.5^7 of them
  // One crossing per message and host, not per service.
  EXPECT_EQ(link.counts().at("SCAN_WORLD").crossing, 500);
}

TEST(LinkFaults, MessagesBetweenHostsAreDelayedByTheDelayPlusJitter) {
  LinkFaultsConfig config = two_hosts(0.0, 3);
  config.delay = 0.05;
  config.jitter = 0.02;
  LinkFaults link(config);
  link.published("vehicle_sim", "NAV_STATE");
  double lo = 1.0, hi = 0.0, sum = 0.0;
  constexpr int kMessages = 2000;
  for (int i = 0; i < kMessages; ++i) {
    link.next_message();
    const auto to_mapper = link.deliver("mapper", "NAV_STATE", 300);
    ASSERT_TRUE(to_mapper.arrives);
    // One fate per message and host.
    EXPECT_EQ(link.deliver("rh_optimizer", "NAV_STATE", 300).delay, to_mapper.delay);
    // Nothing within a host.
    EXPECT_EQ(link.deliver("controller", "NAV_STATE", 300).delay, 0.0);
    lo = std::min(lo, to_mapper.delay);
    hi = std::max(hi, to_mapper.delay);
    sum += to_mapper.delay;
  }
  EXPECT_GE(lo, 0.03 - 1e-12);
  EXPECT_LE(hi, 0.07 + 1e-12);
  EXPECT_LT(lo, 0.032);
  EXPECT_GT(hi, 0.068);
  EXPECT_NEAR(sum / kMessages, 0.05, 0.002);
}

TEST(LinkFaults, AllLinksDelaysTheServicesOfOneHostButNotTheirOwnMessages) {
  LinkFaultsConfig config = two_hosts(0.0);
  config.delay = 0.02;
  config.all_links = true;
  LinkFaults link(config);
  link.published("vehicle_sim", "NAV_STATE");
  link.next_message();
  EXPECT_DOUBLE_EQ(link.deliver("controller", "NAV_STATE", 300).delay, 0.02);
  EXPECT_DOUBLE_EQ(link.deliver("mapper", "NAV_STATE", 300).delay, 0.02);
  EXPECT_EQ(link.deliver("vehicle_sim", "NAV_STATE", 300).delay, 0.0);
  LinkFaultsConfig bad = two_hosts(0.0);
  bad.delay = -0.01;
  EXPECT_THROW(LinkFaults{bad}, std::invalid_argument);
  bad.delay = 0.0;
  bad.jitter = std::nan("");
  EXPECT_THROW(LinkFaults{bad}, std::invalid_argument);
}

TEST(LinkFaults, TheSameSeedLosesTheSameMessages) {
  auto pattern = [](uint64_t seed) {
    LinkFaults link(two_hosts(0.3, seed));
    link.published("mapper", "CUBOIDS");
    std::vector<bool> got;
    for (int i = 0; i < 200; ++i) {
      link.next_message();
      got.push_back(link.deliver("controller", "CUBOIDS", 3000).arrives);
    }
    return got;
  };
  EXPECT_EQ(pattern(3), pattern(3));
  EXPECT_NE(pattern(3), pattern(4));
}

TEST(LinkFaults, ABadProbabilityOrAnUnknownServiceIsAnError) {
  EXPECT_THROW(LinkFaults(two_hosts(1.0)), std::invalid_argument);
  EXPECT_THROW(LinkFaults(two_hosts(-0.1)), std::invalid_argument);
  EXPECT_THROW(LinkFaults(two_hosts(std::nan(""))), std::invalid_argument);
  LinkFaults link(two_hosts(0.1));
  EXPECT_THROW(link.published("stranger", "NAV_STATE"), std::out_of_range);
  link.published("vehicle_sim", "NAV_STATE");
  EXPECT_THROW(link.deliver("stranger", "NAV_STATE", 100).arrives, std::out_of_range);
  // A message no service published (a test's own) crosses no link.
  EXPECT_TRUE(link.deliver("mapper", "NOT_PUBLISHED", 100).arrives);
}

TEST(LinkFaults, TheProcessTableGivesEachServiceItsHost) {
  const auto hosts = load_service_hosts(std::string(OFN_SOURCE_DIR) + "/deploy/processes.yaml");
  EXPECT_EQ(hosts.at("controller"), "onboard1");
  EXPECT_EQ(hosts.at("vehicle_sim"), "onboard1");
  EXPECT_EQ(hosts.at("rh_optimizer"), "onboard2");
  EXPECT_EQ(hosts.at("mission_uplink"), "gcs");
  EXPECT_THROW(load_service_hosts("/nonexistent/processes.yaml"), ConfigError);
  const std::string empty = testing::TempDir() + "/empty_processes.yaml";
  std::ofstream(empty) << "processes: []\n";
  EXPECT_THROW(load_service_hosts(empty), ConfigError);
  std::remove(empty.c_str());
}

// Every subscription goes through the link: a message lost on the way is
// never seen, counted neither received nor rejected.
TEST(LinkFaults, ANodeOnALossyLinkNeverSeesALostMessage) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  ManualClock clock(10 * kMicrosPerSecond);
  auto link = std::make_shared<LinkFaults>(two_hosts(0.0));
  link->watch(lcm);
  attach_link_model(lcm, link);
  Node sender("vehicle_sim", lcm, clock);
  Node same_host("controller", lcm, clock);
  Node other_host("mapper", lcm, clock);
  int on_same = 0, on_other = 0;
  same_host.subscribe<nav_state_t>("NAV_STATE", [&](const nav_state_t&) { ++on_same; });
  other_host.subscribe<nav_state_t>("NAV_STATE", [&](const nav_state_t&) { ++on_other; });
  nav_state_t m{};
  m.utime = clock.now();
  m.frame = "NED";
  m.quaternion[0] = 1.0;
  sender.publish("NAV_STATE", m);
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(on_same, 1);
  EXPECT_EQ(on_other, 1);
  EXPECT_EQ(link->counts().at("NAV_STATE").crossing, 1);
  detach_link_model(lcm);

  // The same with half the datagrams between hosts lost.
  lcm::LCM lossy("memq://");
  auto all_lost = std::make_shared<LinkFaults>(two_hosts(0.5, 5));
  all_lost->watch(lossy);
  attach_link_model(lossy, all_lost);
  Node sender2("vehicle_sim", lossy, clock);
  Node same2("controller", lossy, clock);
  Node other2("mapper", lossy, clock);
  Node other3("rh_optimizer", lossy, clock);
  int got_same = 0, got_other = 0;
  std::vector<int64_t> by_mapper, by_optimizer;
  same2.subscribe<nav_state_t>("NAV_STATE", [&](const nav_state_t&) { ++got_same; });
  other2.subscribe<nav_state_t>("NAV_STATE", [&](const nav_state_t& n) {
    ++got_other;
    by_mapper.push_back(n.utime);
  });
  other3.subscribe<nav_state_t>("NAV_STATE",
                                [&](const nav_state_t& n) { by_optimizer.push_back(n.utime); });
  for (int i = 0; i < 50; ++i) {
    m.utime = clock.now() - i;
    sender2.publish("NAV_STATE", m);
  }
  while (lossy.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(got_same, 50);
  EXPECT_GT(got_other, 10);  // half of 50 expected
  EXPECT_LT(got_other, 40);
  // The two services of the other host got the same messages.
  EXPECT_EQ(by_mapper, by_optimizer);
  // A lost message was never received: it is not counted as rejected.
  EXPECT_EQ(other2.counters().rejected, 0);
  EXPECT_EQ(other2.counters().received, got_other);
  detach_link_model(lossy);
}

// A delayed message waits in the node until its time comes, is announced
// as the node's next deadline, and one with a shorter delay overtakes it.
TEST(LinkFaults, ANodeHoldsADelayedMessageUntilItsTime) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  ManualClock clock(10 * kMicrosPerSecond);
  LinkFaultsConfig config = two_hosts(0.0, 9);
  config.delay = 0.05;
  config.jitter = 0.04;
  auto link = std::make_shared<LinkFaults>(config);
  link->watch(lcm);
  attach_link_model(lcm, link);
  Node sender("vehicle_sim", lcm, clock);
  Node near("controller", lcm, clock);
  Node far("mapper", lcm, clock);
  std::vector<Utime> near_got, far_got;
  near.subscribe<nav_state_t>("NAV_STATE",
                              [&](const nav_state_t& n) { near_got.push_back(n.utime); });
  far.subscribe<nav_state_t>("NAV_STATE",
                             [&](const nav_state_t& n) { far_got.push_back(n.utime); });
  // Let the nodes schedule their timers (heartbeats) first.
  for (Node* n : {&sender, &near, &far}) n->fire_due_timers();
  nav_state_t m{};
  m.frame = "NED";
  m.quaternion[0] = 1.0;
  for (int i = 0; i < 20; ++i) {
    m.utime = clock.now() - 20 + i;  // distinct, in sending order
    sender.publish("NAV_STATE", m);
  }
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(near_got.size(), 20u);  // same host: at once
  EXPECT_TRUE(far_got.empty());
  const Utime first_due = far.next_deadline();
  EXPECT_GE(first_due, clock.now() + to_utime(0.01) - 1);
  EXPECT_LE(first_due, clock.now() + to_utime(0.09) + 1);
  // Step the clock to each deadline as the lockstep runner does.
  for (int step = 0; step < 100 && far_got.size() < 20; ++step) {
    clock.set(std::max(clock.now(), far.next_deadline()));
    far.fire_due_timers();
  }
  ASSERT_EQ(far_got.size(), 20u);
  EXPECT_LE(clock.now(), 10 * kMicrosPerSecond + to_utime(0.09) + 1);
  EXPECT_FALSE(std::is_sorted(far_got.begin(), far_got.end()))
      << "with 40 ms of jitter some of 20 messages 0 s apart overtake others";
  EXPECT_EQ(far.counters().received, 20);
  detach_link_model(lcm);
}

}  // namespace
}  // namespace ofn::sim
