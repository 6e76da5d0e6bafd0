#pragma once
// The bus fuzz's messages: for every channel of the channel table
// (ofn/common/channel_table.hpp), a valid message of the channel's type
// (its seed: MessageSupport's, or one heard on the bus) made wrong in one
// place at a time, every field of it in turn (lcm_schema.hpp finds the
// fields), cycling through:
//
//   truncated         the seed cut short: empty, inside and just after the
//                     fingerprint, at and inside every field
//   wrong_fingerprint the seed's body behind a zero, flipped, byte-swapped
//                     or other type's fingerprint; another channel's whole
//                     message
//   size_field        each array count set to -1, -2^31, 2^31 - 1, 2^30,
//                     2^26, 2^16, the bytes left + 1, one more, one less
//   string_length     each string length set to 0, -1, -2^31, 2^31 - 1,
//                     2^26, one more, one less
//   non_finite        each float and double set to a quiet, signalling and
//                     negative NaN, +Inf and -Inf
//   extreme_number    each float and double set to +-max and the smallest
//                     denormal; each other integer to its min, max and -1;
//                     each boolean to 2 and 255
//   stamp             each stamp (utime, *_utime) set to 0, 1 us, -1,
//                     -2^63, 2^63 - 1, and now -+ 10^3, 10^6 and 10^9 s
//   random_bytes      up to 2,000 random bytes
//   noise             the seed with up to 8 random bytes overwritten
//                     after its fingerprint
//   oversized         the seed padded beyond the channel's cap
//
// Pure: no bus, no clock; the caller says what time it is. The same
// generator seed gives the same messages.

#include <cstddef>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "ofn/common/channel_table.hpp"
#include "ofn/common/time.hpp"
#include "ofn/fuzz/lcm_schema.hpp"
#include "ofn/fuzz/message_support.hpp"

namespace ofn::fuzz {

enum class Kind {
  kTruncated,
  kWrongFingerprint,
  kSizeField,
  kStringLength,
  kNonFinite,
  kExtremeNumber,
  kStamp,
  kRandomBytes,
  kNoise,
  kOversized,
};
constexpr int kKindCount = 10;

/// "truncated", "wrong_fingerprint", ...
const char* kind_name(Kind kind);

/// One fuzz message.
struct FuzzMessage {
  std::string channel;
  Kind kind = Kind::kRandomBytes;
  std::vector<uint8_t> bytes;
  /// The type and the place and value the fuzz wrote ("nav_state_t
  /// position[1] = NaN").
  std::string what;
  /// True when the channel type's decode and validate() accept it (an
  /// extreme but finite number, a stamp other than utime): only a
  /// receiver's time check and its own judgement stand before it.
  bool valid = false;
};

/// The cases of one seed: which place, which value. `variant` picks the
/// value of its kind's list.
struct Mutation {
  Kind kind;
  size_t slot;  // index into the seed's slots (unused for some kinds)
  int variant;
};

/// Every mutation of a seed whose fields are `slots`, in a fixed order:
/// each place with each value of its kind, `other_types` other
/// fingerprints and `other_channels` other channels' messages, then
/// `random_share` as many random_bytes and as many noise cases as there
/// are others, and one oversized.
std::vector<Mutation> mutations_of(const std::vector<Slot>& slots, size_t other_types,
                                   size_t other_channels, double random_share = 0.1);

class Fuzzer {
 public:
  /// One fuzzed channel per entry of `table`; the family of heartbeat
  /// channels (a prefix) as `family_names` (e.g. HEARTBEAT_CONTROLLER),
  /// used in turn. Throws std::runtime_error, naming the channel, for an
  /// entry whose type has no MessageSupport (no generator) or no .lcm
  /// definition, or whose generated fingerprint is not the definition's,
  /// or a family with no names.
  Fuzzer(const Schema& schema, const std::vector<ChannelInfo>& table,
         const std::vector<MessageSupport>& supports,
         std::map<std::string, std::vector<std::string>> family_names, uint64_t seed);

  /// The channel names fuzzed, the families' names included.
  std::vector<std::string> channels() const;

  /// Makes `data`, heard on `channel`, that channel's seed when its type's
  /// check accepts it, its stamps lie within `near` of `now` (not one of
  /// this fuzz's far stamps), and it is at most `max_bytes` long. True
  /// when taken.
  bool offer_seed(const std::string& channel, const uint8_t* data, size_t size, Utime now,
                  Utime near, size_t max_bytes);

  /// The next message: the channels in turn, each one's mutations in turn;
  /// the seed stamped `now` first.
  FuzzMessage next(Utime now);

  /// Every mutation of `channel`'s current seed, made at `now` (tests).
  std::vector<FuzzMessage> all_of(const std::string& channel, Utime now);

  /// How many mutations one cycle of `channel`'s seed has.
  size_t cycle_length(const std::string& channel) const;

 private:
  struct Channel {
    const ChannelInfo* info;
    const MessageSupport* support;
    std::vector<std::string> names;  // the channel, or its family's names
    size_t next_name = 0;
    std::vector<uint8_t> seed;
    std::vector<Slot> slots;
    std::vector<Mutation> mutations;
    size_t next_mutation = 0;
  };

  void set_seed(Channel& c, std::vector<uint8_t> bytes);
  FuzzMessage make(Channel& c, const Mutation& m, Utime now);
  Channel* find(const std::string& channel);

  const Schema& schema_;
  std::vector<Channel> channels_;
  std::vector<int64_t> fingerprints_;  // of every type of the schema
  size_t next_channel_ = 0;
  std::mt19937_64 rng_;
};

}  // namespace ofn::fuzz
