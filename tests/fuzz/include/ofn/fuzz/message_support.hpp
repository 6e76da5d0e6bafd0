#pragma once
// What the bus fuzz knows of each message type through its generated C++
// class: a valid message to mutate, the receivers' own acceptance test
// (decode and validate(), as a Node does before its time check), and a
// subscription on a Node. One entry per type a channel of the channel
// table carries (ofn/common/channel_table.hpp); a channel whose type has
// none has no generator, and the fuzz refuses to start.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ofn/common/node.hpp"

namespace ofn::fuzz {

struct MessageSupport {
  /// The LCM type's short name, "nav_state_t".
  std::string type;
  /// The generated class's getHash().
  int64_t fingerprint = 0;
  /// A valid message (one validate() accepts), encoded with its
  /// fingerprint, every array holding a few elements and every string a
  /// few characters; stamps 0 (the fuzz stamps it).
  std::function<std::vector<uint8_t>()> seed;
  /// Empty when a receiver's decode and validate() accept `data` (exactly
  /// one message, or one and an authentication trailer), else why not.
  std::function<std::string(const uint8_t* data, size_t size)> check;
  /// The message in `data` encoded again without what followed it (an
  /// authentication trailer), or nullopt when it does not decode.
  std::function<std::optional<std::vector<uint8_t>>(const uint8_t* data, size_t size)> reencode;
  /// Subscribes `on_accepted` on `node` to `channel` as a service would
  /// (Node::subscribe of the type, with `options`).
  std::function<void(Node& node, const std::string& channel, SubscribeOptions options,
                     std::function<void()> on_accepted)>
      subscribe;
};

/// One entry per message type of the channel table.
const std::vector<MessageSupport>& message_supports();

/// The entry of `type`, or nullptr.
const MessageSupport* find_message_support(const std::string& type);

}  // namespace ofn::fuzz
