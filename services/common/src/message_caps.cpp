#include "ofn/common/message_caps.hpp"

#include <algorithm>

#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channel_table.hpp"

namespace ofn {

// The caps themselves, and why each is what it is, are the channel table's
// (channel_table.cpp).
size_t max_message_bytes(const std::string& channel) {
  if (const ChannelInfo* entry = find_channel(channel)) return entry->max_bytes;
  static const size_t largest =
      std::max_element(channel_table().begin(), channel_table().end(),
                       [](const auto& a, const auto& b) { return a.max_bytes < b.max_bytes; })
          ->max_bytes;
  return largest;
}

size_t max_received_bytes(const std::string& channel) {
  return max_message_bytes(channel) + bus_auth::kMaxTrailerBytes;
}

}  // namespace ofn
