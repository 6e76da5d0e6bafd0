#pragma once
// Every channel of the bus, once: its name, the LCM type it carries and its
// size cap. The bus contract that the size caps (message_caps.hpp), the
// bus fuzz (tests/fuzz) and the tests that walk every channel read, so a
// channel added here is capped and fuzzed, and one missing here is neither.

#include <cstddef>
#include <string>
#include <vector>

namespace ofn {

struct ChannelInfo {
  /// The channel's name (ofn/common/channels.hpp); for a family of channels
  /// (HEARTBEAT_<SERVICE>) the prefix they share.
  const char* name;
  /// The LCM type it carries, as lcmtypes/<type>.lcm names it ("nav_state_t").
  const char* type;
  /// The largest message it carries, bytes of LCM payload (without an
  /// authentication trailer); the table in channel_table.cpp says why.
  size_t max_bytes;
  /// True for a family of channels named `name` + a suffix.
  bool prefix = false;

  /// True when `channel` is this entry's channel or one of its family.
  bool matches(const std::string& channel) const;
};

/// Every channel, in the order of ofn/common/channels.hpp, the heartbeat
/// family last.
const std::vector<ChannelInfo>& channel_table();

/// The entry `channel` belongs to, or nullptr for a channel of no entry (a
/// test's, a tool's).
const ChannelInfo* find_channel(const std::string& channel);

}  // namespace ofn
