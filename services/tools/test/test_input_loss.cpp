// What the services' heartbeats say they lost: totals per service and
// channel across restarts, what grew since the last look, and the line that
// shows it.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ofn/tools/input_loss.hpp"

namespace ofn::report {
namespace {

heartbeat_t heartbeat(const std::string& service, int32_t pid,
                      const std::vector<channel_counts_t>& inputs) {
  heartbeat_t m{};
  m.service = service;
  m.pid = pid;
  m.inputs = inputs;
  m.num_inputs = static_cast<int32_t>(inputs.size());
  return m;
}

channel_counts_t input(const std::string& channel, int64_t received, int64_t lost,
                       int64_t duplicated = 0) {
  channel_counts_t c{};
  c.channel = channel;
  c.received = received;
  c.lost = lost;
  c.duplicated = duplicated;
  c.publishers = 1;
  return c;
}

TEST(InputLossTally, TotalsAreTheLastHeartbeatsPerServiceAndChannel) {
  InputLossTally tally;
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 100, 2), input("SCAN_WORLD", 12, 5)}));
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 200, 3), input("SCAN_WORLD", 25, 9)}));
  tally.heard(heartbeat("controller", 11, {input("NAV_STATE", 210, 0)}));
  const auto totals = tally.totals();
  ASSERT_EQ(totals.size(), 3u);
  EXPECT_EQ(totals[0].service, "controller");
  EXPECT_EQ(totals[0].counts.lost, 0);
  EXPECT_EQ(totals[1].service, "mapper");
  EXPECT_EQ(totals[1].channel, "NAV_STATE");
  EXPECT_EQ(totals[1].counts.received, 200);
  EXPECT_EQ(totals[1].counts.lost, 3);
  EXPECT_EQ(totals[2].channel, "SCAN_WORLD");
  EXPECT_EQ(totals[2].counts.lost, 9);
}

TEST(InputLossTally, ARestartedServiceAddsToWhatItsEarlierProcessCounted) {
  InputLossTally tally;
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 500, 7)}));
  // Another pid: a new process, counting from zero.
  tally.heard(heartbeat("mapper", 42, {input("NAV_STATE", 50, 1)}));
  EXPECT_EQ(tally.totals().at(0).counts.received, 550);
  EXPECT_EQ(tally.totals().at(0).counts.lost, 8);
  // The same pid with fewer messages (a container's pid 1): restarted too.
  tally.heard(heartbeat("mapper", 42, {input("NAV_STATE", 60, 1)}));
  tally.heard(heartbeat("mapper", 42, {input("NAV_STATE", 5, 0)}));
  EXPECT_EQ(tally.totals().at(0).counts.received, 565);
  EXPECT_EQ(tally.totals().at(0).counts.lost, 8);
}

TEST(InputLossTally, GrownNamesOnlyTheInputsThatLostOrDuplicatedMoreSinceTheLastCall) {
  InputLossTally tally;
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 100, 0), input("SCAN_WORLD", 10, 0)}));
  EXPECT_TRUE(tally.grown().empty());
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 200, 0), input("SCAN_WORLD", 20, 4)}));
  auto grown = tally.grown();
  ASSERT_EQ(grown.size(), 1u);
  EXPECT_EQ(grown[0].channel, "SCAN_WORLD");
  EXPECT_EQ(grown[0].new_lost, 4);
  EXPECT_TRUE(tally.grown().empty());
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 300, 0, 2), input("SCAN_WORLD", 30, 4)}));
  grown = tally.grown();
  ASSERT_EQ(grown.size(), 1u);
  EXPECT_EQ(grown[0].channel, "NAV_STATE");
  EXPECT_EQ(grown[0].new_lost, 0);
  EXPECT_EQ(grown[0].new_duplicated, 2);
}

TEST(InputLossTally, AFloodOfMadeUpNamesIsBounded) {
  InputLossTally tally;
  for (size_t i = 0; i < InputLossTally::kMaxEntries + 10; ++i)
    tally.heard(heartbeat("s" + std::to_string(i), 1, {input("X", 1, 0)}));
  EXPECT_EQ(tally.totals().size(), InputLossTally::kMaxEntries);
  EXPECT_EQ(tally.ignored(), 10);
}

TEST(InputLoss, TheLineSaysHowManyOfHowManySentWereLost) {
  InputTotal in{"rh_optimizer", "NAV_STATE", {}};
  // 3,014 received, 2 of them copies, none unsequenced, 37 lost: 3,049 sent.
  in.counts.received = 3014;
  in.counts.duplicated = 2;
  in.counts.lost = 37;
  EXPECT_EQ(sequenced_sent(in.counts), 3049);
  EXPECT_EQ(describe(in), "rh_optimizer NAV_STATE: 37 of 3049 lost (1.2 %), 2 duplicated");
  // Unsequenced messages were not numbered: not part of what was sent.
  in.counts.unsequenced = 14;
  in.counts.duplicated = 0;
  EXPECT_EQ(describe(in), "rh_optimizer NAV_STATE: 37 of 3037 lost (1.2 %)");
  InputTotal none{"mapper", "SCAN_WORLD", {}};
  EXPECT_EQ(describe(none), "mapper SCAN_WORLD: 0 of 0 lost");
}

TEST(InputLoss, GrowthIsOneLinePerService) {
  InputLossTally tally;
  tally.heard(heartbeat("mapper", 10, {input("NAV_STATE", 100, 3), input("SCAN_WORLD", 10, 10)}));
  tally.heard(heartbeat("controller", 11, {input("MISSION", 9, 1, 1)}));
  const auto lines = growth_lines(tally.grown());
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "controller: MISSION +1 lost (1 of 9, 11.1 %), +1 duplicated");
  EXPECT_EQ(lines[1],
            "mapper: NAV_STATE +3 lost (3 of 103, 2.9 %); SCAN_WORLD +10 lost (10 of 20, 50.0 %)");
  EXPECT_TRUE(growth_lines(tally.grown()).empty());
}

}  // namespace
}  // namespace ofn::report
