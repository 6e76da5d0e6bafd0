#pragma once
// What the launcher's hang watchdog hears (deploy/launch.py): every
// heartbeat on the bus, checked as a Node checks what it receives (the
// channel's size cap, on an authenticated bus the signature, the decode
// and validate), each reduced to one line for the launcher to read:
//
//   heartbeat <channel> <pid> <utime>
//
// Pure: bytes in, a line out; ofn_heartbeat_probe wires it to LCM.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "ofn/bus_auth/authenticator.hpp"

namespace ofn::report {

class HeartbeatProbe {
 public:
  /// With a verifier, only heartbeats signed by a role allowed to publish
  /// on their channel are heard (an authenticated bus).
  explicit HeartbeatProbe(std::optional<bus_auth::Verifier> verifier = std::nullopt);

  /// The line for one message received on `channel` (a HEARTBEAT_<NAME>
  /// channel), without a newline; empty when it is refused, which
  /// refused() counts and last_reason() explains.
  std::string line(const std::string& channel, const void* data, size_t size);

  int64_t heard() const { return heard_; }
  int64_t refused() const { return refused_; }
  const std::string& last_reason() const { return last_reason_; }

 private:
  std::string refuse(const std::string& channel, const std::string& reason);

  std::optional<bus_auth::Verifier> verifier_;
  int64_t heard_ = 0;
  int64_t refused_ = 0;
  std::string last_reason_;
};

}  // namespace ofn::report
