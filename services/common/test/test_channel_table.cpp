// The channel table: every channel of channels.hpp in it once, each with a
// message type that lcmtypes/ defines and a cap.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "ofn/common/channel_table.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/message_caps.hpp"

namespace ofn {
namespace {

std::string read_source(const std::string& path) {
  std::ifstream in(std::string(OFN_SOURCE_DIR) + "/" + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ChannelTable, HoldsEveryChannelOfChannelsHppOnce) {
  // Read from the header itself, so a channel added there and forgotten
  // here fails.
  const std::string header = read_source("services/common/include/ofn/common/channels.hpp");
  const std::regex constant(R"re(inline constexpr const char\* k\w+ = "([A-Z_]+)";)re");
  std::set<std::string> declared;
  for (auto it = std::sregex_iterator(header.begin(), header.end(), constant);
       it != std::sregex_iterator(); ++it)
    declared.insert((*it)[1]);
  ASSERT_GE(declared.size(), 16u) << "channels.hpp not read";
  std::set<std::string> listed;
  for (const auto& entry : channel_table()) {
    EXPECT_TRUE(listed.insert(entry.name).second) << entry.name << " listed twice";
    EXPECT_TRUE(declared.count(entry.name)) << entry.name << " is not in channels.hpp";
  }
  EXPECT_EQ(listed, declared);
}

TEST(ChannelTable, EachTypeIsDefinedInLcmtypesAndEachChannelCapped) {
  for (const auto& entry : channel_table()) {
    std::ifstream lcm(std::string(OFN_SOURCE_DIR) + "/lcmtypes/" + entry.type + ".lcm");
    EXPECT_TRUE(lcm.good()) << entry.name << ": no lcmtypes/" << entry.type << ".lcm";
    EXPECT_GE(entry.max_bytes, 1024u) << entry.name;
    EXPECT_EQ(max_message_bytes(entry.prefix ? std::string(entry.name) + "X" : entry.name),
              entry.max_bytes)
        << entry.name;
  }
}

TEST(ChannelTable, FindsAChannelAndTheHeartbeatFamily) {
  ASSERT_NE(find_channel(channels::kRefTraj), nullptr);
  EXPECT_STREQ(find_channel(channels::kRefTraj)->type, "ref_traj_t");
  ASSERT_NE(find_channel("HEARTBEAT_MAPPER"), nullptr);
  EXPECT_STREQ(find_channel("HEARTBEAT_MAPPER")->type, "heartbeat_t");
  EXPECT_TRUE(find_channel("HEARTBEAT_MAPPER")->prefix);
  EXPECT_EQ(find_channel("HEARTBEAT_"), nullptr);  // the prefix alone is no service's
  EXPECT_EQ(find_channel("NAV_STATE_X"), nullptr);
  EXPECT_EQ(find_channel("SOMETHING_ELSE"), nullptr);
}

}  // namespace
}  // namespace ofn
