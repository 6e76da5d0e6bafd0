#pragma once
// The largest message each channel carries, in bytes of the LCM payload: a
// message larger than its channel's cap (plus, at most, its sequence and
// authentication trailers) is dropped by the Node before it is decoded, counted and logged
// as a rejection of kind "oversized". The caps are the channel table's
// (ofn/common/channel_table.hpp), with the largest message measured in a
// flight and the bound each cap leaves above it.
//
// LCM itself has received the whole message by then (it reassembles the
// datagrams of a large one into a buffer of the announced size): the cap
// spares the decoder, the validation and the service's handler, not LCM's
// receive buffer.

#include <cstddef>
#include <string>

namespace ofn {

/// The cap of `channel`, bytes of LCM payload; HEARTBEAT_<NAME> channels
/// share one. A channel the table does not name (a test's, a tool's) gets
/// the largest cap of the table.
size_t max_message_bytes(const std::string& channel);

/// The largest received size `channel` accepts: its cap and room for the
/// sequence trailer and an authentication trailer
/// (ofn/bus_auth/trailer.hpp), which an open bus ignores and an
/// authenticated one requires.
size_t max_received_bytes(const std::string& channel);

}  // namespace ofn
