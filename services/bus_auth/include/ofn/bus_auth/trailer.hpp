#pragma once
// Wire format of a message on the project's bus: the LCM payload exactly as
// lcm-gen encodes it (8-byte fingerprint first), then fixed-size trailers.
// LCM's own decoders (C++, Java in lcm-spy, Python) read a message from the
// front and stop at its end, so lcm-spy shows the traffic and lcm-logger /
// lcm-logplayer record and replay it byte for byte.
//
//   payload | sequence trailer | authentication trailer (authenticated bus)
//
// The sequence trailer (20 bytes; every Node publishes it, on either bus):
//
//   publisher id (uint64, big endian) | sequence (uint64, big endian)
//           | magic "OFS1" (4 bytes)
//
// The publisher id names one publishing Node (a process's random number
// mixed with the node's name); the sequence counts that node's messages on
// the channel from 1, so a receiver sees a gap, a copy or a restarted
// publisher (a new id).
//
// The authentication trailer (92 bytes):
//
//   role (16 bytes, NUL padded) | sequence (uint64, big endian)
//           | Ed25519 signature (64 bytes) | magic "OFA1" (4 bytes)
//
// Its sequence is the sending host's wall clock in microseconds (freshness
// and replay). The signature covers a domain tag, the channel name, all the
// bytes before the authentication trailer (payload and sequence trailer),
// the role and that sequence, so a message cannot be moved to another
// channel, altered, renumbered or claimed by another role.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace ofn::bus_auth {

inline constexpr size_t kRoleBytes = 16;
inline constexpr size_t kSequenceBytes = 8;
inline constexpr size_t kSignatureBytes = 64;
inline constexpr std::array<char, 4> kTrailerMagic{'O', 'F', 'A', '1'};
/// The authentication trailer.
inline constexpr size_t kTrailerBytes =
    kRoleBytes + kSequenceBytes + kSignatureBytes + kTrailerMagic.size();

inline constexpr size_t kPublisherIdBytes = 8;
inline constexpr std::array<char, 4> kSequenceTrailerMagic{'O', 'F', 'S', '1'};
/// The sequence trailer.
inline constexpr size_t kSequenceTrailerBytes =
    kPublisherIdBytes + kSequenceBytes + kSequenceTrailerMagic.size();
/// The most a message carries after its payload: both trailers.
inline constexpr size_t kMaxTrailerBytes = kSequenceTrailerBytes + kTrailerBytes;

inline void put_be64(uint8_t* out, uint64_t value) {
  for (int i = 7; i >= 0; --i) {
    out[i] = static_cast<uint8_t>(value & 0xff);
    value >>= 8;
  }
}

inline uint64_t get_be64(const uint8_t* in) {
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = (value << 8) | in[i];
  return value;
}

namespace detail {
template <size_t N>
bool ends_with(const void* data, size_t size, size_t trailer_bytes,
               const std::array<char, N>& magic) {
  if (size < trailer_bytes) return false;
  const auto* end = static_cast<const uint8_t*>(data) + size;
  return std::memcmp(end - N, magic.data(), N) == 0;
}
}  // namespace detail

/// True when the `size` bytes at `data` end with an authentication trailer
/// (by its magic; the signature is not checked).
inline bool ends_with_trailer(const void* data, size_t size) {
  return detail::ends_with(data, size, kTrailerBytes, kTrailerMagic);
}

/// True when the `size` bytes at `data` end with a sequence trailer (by its
/// magic).
inline bool ends_with_sequence_trailer(const void* data, size_t size) {
  return detail::ends_with(data, size, kSequenceTrailerBytes, kSequenceTrailerMagic);
}

/// One publisher's number for one message on one channel.
struct SequenceStamp {
  uint64_t publisher = 0;
  uint64_t sequence = 0;
};

/// Appends a sequence trailer to `message` (an encoded LCM payload).
inline void append_sequence_trailer(std::vector<uint8_t>& message, const SequenceStamp& stamp) {
  const size_t at = message.size();
  message.resize(at + kSequenceTrailerBytes);
  put_be64(message.data() + at, stamp.publisher);
  put_be64(message.data() + at + kPublisherIdBytes, stamp.sequence);
  std::memcpy(message.data() + at + kPublisherIdBytes + kSequenceBytes,
              kSequenceTrailerMagic.data(), kSequenceTrailerMagic.size());
}

/// The stamp of the sequence trailer that `data` ends with
/// (ends_with_sequence_trailer must hold).
inline SequenceStamp read_sequence_trailer(const void* data, size_t size) {
  const auto* trailer = static_cast<const uint8_t*>(data) + size - kSequenceTrailerBytes;
  return {get_be64(trailer), get_be64(trailer + kPublisherIdBytes)};
}

/// The bytes of a received message before its trailers, by their magic
/// alone (nothing decoded or checked): what a comparison of payloads reads.
inline size_t payload_bytes(const void* data, size_t size) {
  if (ends_with_trailer(data, size)) size -= kTrailerBytes;
  if (ends_with_sequence_trailer(data, size)) size -= kSequenceTrailerBytes;
  return size;
}

/// What followed a decoded message.
struct Trailers {
  bool sequenced = false;  // a sequence trailer, whose stamp is `sequence`
  SequenceStamp sequence;
  bool signed_ = false;  // an authentication trailer (not checked here)
};

/// Decodes one LCM message from a buffer that holds it alone, or it and
/// its trailers: a sequence trailer, an authentication trailer, or both in
/// that order (the authentication trailer is not checked here: a service
/// that authenticates checks it before, and passes the bytes before it).
/// A trailer is taken only where the decoded message ends, so a payload
/// that happens to end like one is not cut. False for anything else: a
/// short or undecodable buffer, or bytes after the message that are not
/// trailers. `trailers`, when given, says what followed.
template <class Msg>
bool decode_payload(Msg& msg, const void* data, size_t size, Trailers* trailers = nullptr) {
  if (size > static_cast<size_t>(INT32_MAX)) return false;
  int decoded = -1;
  try {
    decoded = msg.decode(data, 0, static_cast<int>(size));
  } catch (...) {
    return false;
  }
  if (decoded < 0) return false;
  const auto used = static_cast<size_t>(decoded);
  Trailers found;
  size_t rest = size - used;
  if (rest >= kTrailerBytes && ends_with_trailer(data, size) &&
      (rest == kTrailerBytes || rest == kMaxTrailerBytes)) {
    found.signed_ = true;
    rest -= kTrailerBytes;
  }
  const size_t before_signature = used + rest;
  if (rest == kSequenceTrailerBytes && ends_with_sequence_trailer(data, before_signature)) {
    found.sequenced = true;
    found.sequence = read_sequence_trailer(data, before_signature);
    rest = 0;
  }
  if (rest != 0) return false;
  if (trailers) *trailers = found;
  return true;
}

}  // namespace ofn::bus_auth
