#include "ofn/fuzz/fuzz_cases.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "ofn/bus_auth/trailer.hpp"

namespace ofn::fuzz {
namespace {

constexpr size_t kMaxRandomBytes = 2000;
constexpr int kMaxNoiseBytes = 8;

// The cuts that are not at a field: empty, inside the fingerprint, the
// fingerprint alone.
constexpr int kFixedCuts[] = {0, 1, 4, 7, 8};

// Wrong fingerprints: these first, then every other type's, then every
// other channel's whole message.
constexpr int kFingerprintForms = 5;  // zero, low bit, high bit, byte-swapped, all ones
constexpr int kOtherChannelBase = 1 << 20;

constexpr int64_t kSizeValues[] = {-1, INT32_MIN, INT32_MAX, int64_t{1} << 30, 1 << 26, 1 << 16};
// and then: the bytes left + 1, one more, one less
constexpr int kSizeVariants = 6 + 3;

constexpr int64_t kLengthValues[] = {0, -1, INT32_MIN, INT32_MAX, 1 << 26};
// and then: one more, one less
constexpr int kLengthVariants = 5 + 2;

constexpr int kNonFiniteVariants = 5;
const char* const kNonFiniteNames[] = {"NaN", "signalling NaN", "-NaN", "+Inf", "-Inf"};
constexpr uint32_t kFloatBits[] = {0x7fc00000u, 0x7fa00000u, 0xffc00000u, 0x7f800000u, 0xff800000u};
constexpr uint64_t kDoubleBits[] = {0x7ff8000000000000ull, 0x7ff4000000000000ull,
                                    0xfff8000000000000ull, 0x7ff0000000000000ull,
                                    0xfff0000000000000ull};

constexpr int kStampVariants = 11;
constexpr Utime kSecond = 1000000;

Utime stamp_value(int variant, Utime now) {
  switch (variant) {
    case 0:
      return 0;
    case 1:
      return 1;
    case 2:
      return -1;
    case 3:
      return INT64_MIN;
    case 4:
      return INT64_MAX;
    case 5:
      return now - 1000 * kSecond;
    case 6:
      return now - 1000000 * kSecond;
    case 7:
      return now - 1000000000 * kSecond;
    case 8:
      return now + 1000 * kSecond;
    case 9:
      return now + 1000000 * kSecond;
    default:
      return now + 1000000000 * kSecond;
  }
}

const char* const kStampNames[] = {"0",
                                   "1 us",
                                   "-1 us",
                                   "-2^63",
                                   "2^63 - 1",
                                   "now - 10^3 s",
                                   "now - 10^6 s",
                                   "now - 10^9 s",
                                   "now + 10^3 s",
                                   "now + 10^6 s",
                                   "now + 10^9 s"};

void write_be(std::vector<uint8_t>& bytes, size_t offset, size_t size, uint64_t value) {
  for (size_t i = 0; i < size; ++i)
    bytes[offset + i] = static_cast<uint8_t>(value >> (8 * (size - 1 - i)));
}

int64_t int_min(size_t size) {
  return size == 1 ? INT8_MIN : size == 2 ? INT16_MIN : size == 4 ? INT32_MIN : INT64_MIN;
}
int64_t int_max(size_t size) {
  return size == 1 ? INT8_MAX : size == 2 ? INT16_MAX : size == 4 ? INT32_MAX : INT64_MAX;
}

bool is_plain_integer(SlotKind k) {
  return k == SlotKind::kInt8 || k == SlotKind::kInt16 || k == SlotKind::kInt32 ||
         k == SlotKind::kInt64;
}

void restamp(std::vector<uint8_t>& bytes, const std::vector<Slot>& slots, Utime now,
             size_t except = SIZE_MAX) {
  for (size_t i = 0; i < slots.size(); ++i)
    if (slots[i].kind == SlotKind::kStamp && i != except)
      write_be(bytes, slots[i].offset, 8, static_cast<uint64_t>(now));
}

}  // namespace

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::kTruncated:
      return "truncated";
    case Kind::kWrongFingerprint:
      return "wrong_fingerprint";
    case Kind::kSizeField:
      return "size_field";
    case Kind::kStringLength:
      return "string_length";
    case Kind::kNonFinite:
      return "non_finite";
    case Kind::kExtremeNumber:
      return "extreme_number";
    case Kind::kStamp:
      return "stamp";
    case Kind::kRandomBytes:
      return "random_bytes";
    case Kind::kNoise:
      return "noise";
    case Kind::kOversized:
      return "oversized";
  }
  return "?";
}

std::vector<Mutation> mutations_of(const std::vector<Slot>& slots, size_t other_types,
                                   size_t other_channels, double random_share) {
  std::vector<Mutation> out;
  // Truncations: the fixed cuts, then at and inside every field (a string
  // also after its length and inside its characters).
  std::vector<int> cuts(std::begin(kFixedCuts), std::end(kFixedCuts));
  for (const auto& s : slots) {
    cuts.push_back(static_cast<int>(s.offset));
    if (s.size > 1) cuts.push_back(static_cast<int>(s.offset + s.size / 2));
    if (s.kind == SlotKind::kStringLength) {
      cuts.push_back(static_cast<int>(s.offset + 4));
      if (s.value > 1) cuts.push_back(static_cast<int>(s.offset + 4 + s.value / 2));
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  for (int cut : cuts) out.push_back({Kind::kTruncated, 0, cut});
  for (int v = 0; v < kFingerprintForms + static_cast<int>(other_types); ++v)
    out.push_back({Kind::kWrongFingerprint, 0, v});
  for (int v = 0; v < static_cast<int>(other_channels); ++v)
    out.push_back({Kind::kWrongFingerprint, 0, kOtherChannelBase + v});
  for (size_t i = 0; i < slots.size(); ++i) {
    const SlotKind k = slots[i].kind;
    if (k == SlotKind::kCount)
      for (int v = 0; v < kSizeVariants; ++v) out.push_back({Kind::kSizeField, i, v});
    if (k == SlotKind::kStringLength)
      for (int v = 0; v < kLengthVariants; ++v) out.push_back({Kind::kStringLength, i, v});
    if (k == SlotKind::kFloat || k == SlotKind::kDouble) {
      for (int v = 0; v < kNonFiniteVariants; ++v) out.push_back({Kind::kNonFinite, i, v});
      for (int v = 0; v < 3; ++v) out.push_back({Kind::kExtremeNumber, i, v});
    }
    if (is_plain_integer(k))
      for (int v = 0; v < 3; ++v) out.push_back({Kind::kExtremeNumber, i, v});
    if (k == SlotKind::kBoolean)
      for (int v = 0; v < 2; ++v) out.push_back({Kind::kExtremeNumber, i, v});
    if (k == SlotKind::kStamp)
      for (int v = 0; v < kStampVariants; ++v) out.push_back({Kind::kStamp, i, v});
  }
  const size_t randoms =
      std::max<size_t>(2, static_cast<size_t>(std::lround(random_share * out.size())));
  for (size_t i = 0; i < randoms; ++i) out.push_back({Kind::kRandomBytes, 0, 0});
  for (size_t i = 0; i < randoms; ++i) out.push_back({Kind::kNoise, 0, 0});
  out.push_back({Kind::kOversized, 0, 0});
  // Interleaved (a fixed stride through the list), so that a short run
  // still has every kind.
  std::vector<Mutation> mixed;
  mixed.reserve(out.size());
  const size_t stride = 7;
  for (size_t start = 0; start < stride; ++start)
    for (size_t i = start; i < out.size(); i += stride) mixed.push_back(out[i]);
  return mixed;
}

Fuzzer::Fuzzer(const Schema& schema, const std::vector<ChannelInfo>& table,
               const std::vector<MessageSupport>& supports,
               std::map<std::string, std::vector<std::string>> family_names, uint64_t seed)
    : schema_(schema), rng_(seed) {
  for (const auto& type : schema.types()) fingerprints_.push_back(schema.fingerprint(type));
  for (const auto& info : table) {
    const auto support = std::find_if(supports.begin(), supports.end(),
                                      [&](const MessageSupport& s) { return s.type == info.type; });
    if (support == supports.end())
      throw std::runtime_error(std::string("channel ") + info.name + ": no fuzz generator for " +
                               info.type + " (tests/fuzz/src/message_support.cpp)");
    if (schema.find(info.type) == nullptr)
      throw std::runtime_error(std::string("channel ") + info.name + ": no definition of " +
                               info.type + " among the .lcm files");
    if (schema.fingerprint(info.type) != support->fingerprint)
      throw std::runtime_error(std::string("channel ") + info.name + ": " + info.type +
                               "'s fingerprint from its .lcm file differs from the generated "
                               "class's");
    Channel c;
    c.info = &info;
    c.support = &*support;
    if (info.prefix) {
      c.names = family_names[info.name];
      if (c.names.empty())
        throw std::runtime_error(std::string("channel family ") + info.name +
                                 "*: no channel names to fuzz it on");
    } else {
      c.names = {info.name};
    }
    channels_.push_back(std::move(c));
  }
  for (auto& c : channels_) set_seed(c, c.support->seed());
}

std::vector<std::string> Fuzzer::channels() const {
  std::vector<std::string> names;
  for (const auto& c : channels_) names.insert(names.end(), c.names.begin(), c.names.end());
  return names;
}

Fuzzer::Channel* Fuzzer::find(const std::string& channel) {
  for (auto& c : channels_)
    if (std::find(c.names.begin(), c.names.end(), channel) != c.names.end()) return &c;
  return nullptr;
}

void Fuzzer::set_seed(Channel& c, std::vector<uint8_t> bytes) {
  c.slots = schema_.walk(c.info->type, bytes.data(), bytes.size());
  c.seed = std::move(bytes);
  c.mutations = mutations_of(c.slots, fingerprints_.size() - 1, channels_.size() - 1);
  c.next_mutation %= c.mutations.size();
}

bool Fuzzer::offer_seed(const std::string& channel, const uint8_t* data, size_t size, Utime now,
                        Utime near, size_t max_bytes) {
  Channel* c = find(channel);
  if (c == nullptr || !c->support->check(data, size).empty()) return false;
  auto bytes = c->support->reencode(data, size);
  if (!bytes || bytes->size() > max_bytes) return false;
  std::vector<Slot> slots;
  try {
    slots = schema_.walk(c->info->type, bytes->data(), bytes->size());
  } catch (const std::invalid_argument&) {
    return false;  // cannot be for what the generated class encoded; refused, not fatal
  }
  for (const auto& s : slots) {
    if (s.kind != SlotKind::kStamp) continue;
    // A stamp of 0 is "none" (solver_stats_t.map_utime before a map).
    if (s.value != 0 && (s.value < now - near || s.value > now + near)) return false;
  }
  set_seed(*c, std::move(*bytes));
  return true;
}

size_t Fuzzer::cycle_length(const std::string& channel) const {
  for (const auto& c : channels_)
    if (std::find(c.names.begin(), c.names.end(), channel) != c.names.end())
      return c.mutations.size();
  throw std::out_of_range("not a fuzzed channel: " + channel);
}

FuzzMessage Fuzzer::next(Utime now) {
  Channel& c = channels_[next_channel_++ % channels_.size()];
  const Mutation m = c.mutations[c.next_mutation];
  c.next_mutation = (c.next_mutation + 1) % c.mutations.size();
  return make(c, m, now);
}

std::vector<FuzzMessage> Fuzzer::all_of(const std::string& channel, Utime now) {
  Channel* c = find(channel);
  if (c == nullptr) throw std::out_of_range("not a fuzzed channel: " + channel);
  std::vector<FuzzMessage> out;
  for (const auto& m : c->mutations) out.push_back(make(*c, m, now));
  return out;
}

FuzzMessage Fuzzer::make(Channel& c, const Mutation& m, Utime now) {
  FuzzMessage out;
  out.channel = c.names[c.next_name];
  c.next_name = (c.next_name + 1) % c.names.size();
  out.kind = m.kind;
  std::vector<uint8_t> bytes = c.seed;
  restamp(bytes, c.slots, now, m.kind == Kind::kStamp ? m.slot : SIZE_MAX);
  const std::string type = c.info->type;
  const Slot* slot = m.slot < c.slots.size() ? &c.slots[m.slot] : nullptr;
  const auto at = [&] { return type + " " + slot->path + " = "; };
  switch (m.kind) {
    case Kind::kTruncated:
      bytes.resize(static_cast<size_t>(m.variant));
      out.what = type + " cut to " + std::to_string(m.variant) + " of " +
                 std::to_string(c.seed.size()) + " bytes";
      break;
    case Kind::kWrongFingerprint: {
      const uint64_t own = static_cast<uint64_t>(c.support->fingerprint);
      if (m.variant >= kOtherChannelBase) {
        // Another channel's whole message, as it would be on its own.
        size_t k = static_cast<size_t>(m.variant - kOtherChannelBase);
        const size_t self = static_cast<size_t>(&c - channels_.data());
        if (k >= self) ++k;
        const Channel& other = channels_[k % channels_.size()];
        bytes = other.seed;
        restamp(bytes, other.slots, now);
        out.what = std::string(other.info->type) + " sent on " + out.channel;
        break;
      }
      uint64_t fp = 0;
      std::string form;
      switch (m.variant) {
        case 0:
          form = "zero";
          break;
        case 1:
          fp = own ^ 1u;
          form = "low bit flipped";
          break;
        case 2:
          fp = own ^ (uint64_t{1} << 63);
          form = "high bit flipped";
          break;
        case 3:
          for (int i = 0; i < 8; ++i) fp |= ((own >> (8 * i)) & 0xffu) << (8 * (7 - i));
          form = "byte-swapped";
          break;
        case 4:
          fp = ~uint64_t{0};
          form = "all ones";
          break;
        default: {
          // The other types' fingerprints, own skipped.
          std::vector<int64_t> others;
          for (int64_t f : fingerprints_)
            if (f != c.support->fingerprint) others.push_back(f);
          fp = static_cast<uint64_t>(
              others[static_cast<size_t>(m.variant - kFingerprintForms) % others.size()]);
          form = "another type's";
        }
      }
      write_be(bytes, 0, 8, fp);
      out.what = type + " body behind a fingerprint: " + form;
      break;
    }
    case Kind::kSizeField: {
      const int64_t bytes_left = static_cast<int64_t>(c.seed.size() - (slot->offset + slot->size));
      int64_t v;
      if (m.variant < 6)
        v = kSizeValues[m.variant];
      else if (m.variant == 6)
        v = bytes_left + 1;
      else if (m.variant == 7)
        v = slot->value + 1;
      else
        v = slot->value - 1;
      write_be(bytes, slot->offset, slot->size, static_cast<uint64_t>(v));
      out.what = at() + std::to_string(v) + " (was " + std::to_string(slot->value) + ")";
      break;
    }
    case Kind::kStringLength: {
      const int64_t v = m.variant < 5    ? kLengthValues[m.variant]
                        : m.variant == 5 ? slot->value + 1
                                         : slot->value - 1;
      write_be(bytes, slot->offset, 4, static_cast<uint64_t>(v));
      out.what = at() + std::to_string(v) + " (was " + std::to_string(slot->value) + ")";
      break;
    }
    case Kind::kNonFinite:
      if (slot->kind == SlotKind::kFloat)
        write_be(bytes, slot->offset, 4, kFloatBits[m.variant]);
      else
        write_be(bytes, slot->offset, 8, kDoubleBits[m.variant]);
      out.what = at() + kNonFiniteNames[m.variant];
      break;
    case Kind::kExtremeNumber: {
      std::string value;
      if (slot->kind == SlotKind::kFloat) {
        const float f[3] = {std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                            std::numeric_limits<float>::denorm_min()};
        uint32_t bits;
        std::memcpy(&bits, &f[m.variant], 4);
        write_be(bytes, slot->offset, 4, bits);
        value = m.variant == 0 ? "FLT_MAX" : m.variant == 1 ? "-FLT_MAX" : "denorm_min";
      } else if (slot->kind == SlotKind::kDouble) {
        const double d[3] = {std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::denorm_min()};
        uint64_t bits;
        std::memcpy(&bits, &d[m.variant], 8);
        write_be(bytes, slot->offset, 8, bits);
        value = m.variant == 0 ? "DBL_MAX" : m.variant == 1 ? "-DBL_MAX" : "denorm_min";
      } else if (slot->kind == SlotKind::kBoolean) {
        const uint8_t b = m.variant == 0 ? 2 : 255;
        bytes[slot->offset] = b;
        value = std::to_string(b);
      } else {
        const int64_t v = m.variant == 0   ? int_min(slot->size)
                          : m.variant == 1 ? int_max(slot->size)
                                           : -1;
        write_be(bytes, slot->offset, slot->size, static_cast<uint64_t>(v));
        value = std::to_string(v);
      }
      out.what = at() + value;
      break;
    }
    case Kind::kStamp:
      write_be(bytes, slot->offset, 8, static_cast<uint64_t>(stamp_value(m.variant, now)));
      out.what = at() + kStampNames[m.variant];
      break;
    case Kind::kRandomBytes: {
      bytes.resize(std::uniform_int_distribution<size_t>(0, kMaxRandomBytes)(rng_));
      for (auto& b : bytes) b = static_cast<uint8_t>(rng_());
      out.what = std::to_string(bytes.size()) + " random bytes";
      break;
    }
    case Kind::kNoise: {
      const int n = std::uniform_int_distribution<int>(1, kMaxNoiseBytes)(rng_);
      if (bytes.size() > 8)
        for (int i = 0; i < n; ++i)
          bytes[std::uniform_int_distribution<size_t>(8, bytes.size() - 1)(rng_)] =
              static_cast<uint8_t>(rng_());
      out.what = type + " with " + std::to_string(n) + " random bytes written over its body";
      break;
    }
    case Kind::kOversized: {
      const size_t size = c.info->max_bytes + bus_auth::kTrailerBytes + 1 +
                          std::uniform_int_distribution<size_t>(0, 1024)(rng_);
      bytes.resize(std::max(size, bytes.size()), 0);
      out.what = type + " padded to " + std::to_string(bytes.size()) + " bytes, over the cap of " +
                 std::to_string(c.info->max_bytes);
      break;
    }
  }
  out.valid = c.support->check(bytes.data(), bytes.size()).empty();
  out.bytes = std::move(bytes);
  return out;
}

}  // namespace ofn::fuzz
