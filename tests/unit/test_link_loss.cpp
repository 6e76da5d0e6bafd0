// The lockstep runner's lossy link: LCM's fragment count, the seeded draws,
// no loss within a host, and the Node hook that applies it.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/sim/link_loss.hpp"

namespace ofn::sim {
namespace {

LinkLossConfig two_hosts(double loss, uint64_t seed = 1) {
  return {loss,
          seed,
          {{"vehicle_sim", "onboard1"},
           {"controller", "onboard1"},
           {"mapper", "onboard2"},
           {"rh_optimizer", "onboard2"}}};
}

TEST(LinkLoss, FragmentsFollowLcmsFraming) {
  EXPECT_EQ(datagrams_for(0), 1u);
  EXPECT_EQ(datagrams_for(kShortMessageMax), 1u);
  EXPECT_EQ(datagrams_for(kShortMessageMax + 1), 2u);
  EXPECT_EQ(datagrams_for(9600), 7u);    // a scan
  EXPECT_EQ(datagrams_for(13000), 10u);  // a plan
}

TEST(LinkLoss, NothingIsLostWithinAHost) {
  LinkLoss link(two_hosts(0.9));
  link.published("vehicle_sim", "NAV_STATE");
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(link.delivers("controller", "NAV_STATE", 20000));
  EXPECT_TRUE(link.counts().empty());
}

TEST(LinkLoss, BetweenHostsTheLossRateIsThatOfEveryFragmentArriving) {
  LinkLoss link(two_hosts(0.1, 7));
  link.published("vehicle_sim", "NAV_STATE");
  link.published("vehicle_sim", "SCAN_WORLD");
  constexpr int kDraws = 20000;
  int small = 0, large = 0;
  for (int i = 0; i < kDraws; ++i) {
    link.next_message();
    small += link.delivers("mapper", "NAV_STATE", 300) ? 1 : 0;
    link.next_message();
    large += link.delivers("mapper", "SCAN_WORLD", 9600) ? 1 : 0;
  }
  EXPECT_NEAR(small / double(kDraws), 0.9, 0.01);
  EXPECT_NEAR(large / double(kDraws), std::pow(0.9, 7), 0.01);  // 48 %
  EXPECT_EQ(link.counts().at("NAV_STATE").crossing, kDraws);
  EXPECT_EQ(link.counts().at("NAV_STATE").lost, kDraws - small);
  EXPECT_EQ(link.counts().at("SCAN_WORLD").lost, kDraws - large);
}

TEST(LinkLoss, TheServicesOfOneHostLoseTheSameMessages) {
  LinkLoss link(two_hosts(0.5, 11));
  link.published("vehicle_sim", "SCAN_WORLD");
  int lost = 0;
  for (int i = 0; i < 500; ++i) {
    link.next_message();
    const bool mapper = link.delivers("mapper", "SCAN_WORLD", 9600);
    ASSERT_EQ(link.delivers("rh_optimizer", "SCAN_WORLD", 9600), mapper) << i;
    lost += mapper ? 0 : 1;
  }
  EXPECT_GT(lost, 400);  // 1 - 0.5^7 of them
  // One crossing per message and host, not per service.
  EXPECT_EQ(link.counts().at("SCAN_WORLD").crossing, 500);
}

TEST(LinkLoss, TheSameSeedLosesTheSameMessages) {
  auto pattern = [](uint64_t seed) {
    LinkLoss link(two_hosts(0.3, seed));
    link.published("mapper", "CUBOIDS");
    std::vector<bool> got;
    for (int i = 0; i < 200; ++i) {
      link.next_message();
      got.push_back(link.delivers("controller", "CUBOIDS", 3000));
    }
    return got;
  };
  EXPECT_EQ(pattern(3), pattern(3));
  EXPECT_NE(pattern(3), pattern(4));
}

TEST(LinkLoss, ABadProbabilityOrAnUnknownServiceIsAnError) {
  EXPECT_THROW(LinkLoss(two_hosts(1.0)), std::invalid_argument);
  EXPECT_THROW(LinkLoss(two_hosts(-0.1)), std::invalid_argument);
  EXPECT_THROW(LinkLoss(two_hosts(std::nan(""))), std::invalid_argument);
  LinkLoss link(two_hosts(0.1));
  EXPECT_THROW(link.published("stranger", "NAV_STATE"), std::out_of_range);
  link.published("vehicle_sim", "NAV_STATE");
  EXPECT_THROW(link.delivers("stranger", "NAV_STATE", 100), std::out_of_range);
  // A message no service published (a test's own) crosses no link.
  EXPECT_TRUE(link.delivers("mapper", "NOT_PUBLISHED", 100));
}

TEST(LinkLoss, TheProcessTableGivesEachServiceItsHost) {
  const auto hosts = load_service_hosts(std::string(OFN_SOURCE_DIR) + "/deploy/processes.yaml");
  EXPECT_EQ(hosts.at("controller"), "onboard1");
  EXPECT_EQ(hosts.at("vehicle_sim"), "onboard1");
  EXPECT_EQ(hosts.at("rh_optimizer"), "onboard2");
  EXPECT_EQ(hosts.at("mission_uplink"), "gcs");
  EXPECT_THROW(load_service_hosts("/nonexistent/processes.yaml"), ConfigError);
  const std::string empty = testing::TempDir() + "/empty_processes.yaml";
  std::ofstream(empty) << "processes: []\n";
  EXPECT_THROW(load_service_hosts(empty), ConfigError);
}

// Every subscription goes through the link: a message lost on the way is
// never seen, counted neither received nor rejected.
TEST(LinkLoss, ANodeOnALossyLinkNeverSeesALostMessage) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  ManualClock clock(10 * kMicrosPerSecond);
  auto link = std::make_shared<LinkLoss>(two_hosts(0.0));
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
  auto all_lost = std::make_shared<LinkLoss>(two_hosts(0.5, 5));
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

}  // namespace
}  // namespace ofn::sim
