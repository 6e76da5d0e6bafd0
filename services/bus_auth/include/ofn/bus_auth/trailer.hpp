#pragma once
// Wire format of an authenticated LCM message: the LCM payload exactly as
// lcm-gen encodes it (8-byte fingerprint first), then a fixed-size trailer.
// LCM's own decoders (C++, Java in lcm-spy, Python) read a message from the
// front and stop at its end, so lcm-spy shows authenticated traffic and
// lcm-logger / lcm-logplayer record and replay it byte for byte.
//
//   payload | role (16 bytes, NUL padded) | sequence (uint64, big endian)
//           | Ed25519 signature (64 bytes) | magic "OFA1" (4 bytes)
//
// The signature covers a domain tag, the channel name, the payload, the
// role and the sequence, so a message cannot be moved to another channel,
// altered, or claimed by another role.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace ofn::bus_auth {

inline constexpr size_t kRoleBytes = 16;
inline constexpr size_t kSequenceBytes = 8;
inline constexpr size_t kSignatureBytes = 64;
inline constexpr std::array<char, 4> kTrailerMagic{'O', 'F', 'A', '1'};
inline constexpr size_t kTrailerBytes =
    kRoleBytes + kSequenceBytes + kSignatureBytes + kTrailerMagic.size();

/// True when the `size` bytes at `data` end with an authentication trailer
/// (by its magic; the signature is not checked).
inline bool ends_with_trailer(const void* data, size_t size) {
  if (size < kTrailerBytes) return false;
  const auto* end = static_cast<const uint8_t*>(data) + size;
  return std::memcmp(end - kTrailerMagic.size(), kTrailerMagic.data(), kTrailerMagic.size()) == 0;
}

/// Decodes one LCM message from a buffer that holds it alone, or it and an
/// authentication trailer (the trailer is not checked here: a service that
/// authenticates checks it before). False for anything else: a short or
/// undecodable buffer, or bytes after the message that are not a trailer.
template <class Msg>
bool decode_payload(Msg& msg, const void* data, size_t size) {
  if (size > static_cast<size_t>(INT32_MAX)) return false;
  int decoded = -1;
  try {
    decoded = msg.decode(data, 0, static_cast<int>(size));
  } catch (...) {
    return false;
  }
  if (decoded < 0) return false;
  const auto used = static_cast<size_t>(decoded);
  if (used == size) return true;
  return size - used == kTrailerBytes && ends_with_trailer(data, size);
}

}  // namespace ofn::bus_auth
