#include "ofn/tools/heartbeat_probe.hpp"

#include <cctype>
#include <utility>

#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/message_caps.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/heartbeat_t.hpp"

namespace ofn::report {

HeartbeatProbe::HeartbeatProbe(std::optional<bus_auth::Verifier> verifier)
    : verifier_(std::move(verifier)) {}

std::string HeartbeatProbe::refuse(const std::string& channel, const std::string& reason) {
  ++refused_;
  last_reason_ = printable(channel) + ": " + reason;
  return "";
}

std::string HeartbeatProbe::line(const std::string& channel, const void* data, size_t size) {
  if (channel.rfind(channels::kHeartbeatPrefix, 0) != 0 ||
      channel.size() == std::string(channels::kHeartbeatPrefix).size())
    return refuse(channel, "not a heartbeat channel");
  // A name the launcher reads as one word: what heartbeat_channel() makes.
  for (char c : channel)
    if (!(std::isupper(static_cast<unsigned char>(c)) ||
          std::isdigit(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      return refuse(channel, "not a heartbeat channel");
  if (size > max_received_bytes(channel)) return refuse(channel, "oversized");
  size_t payload = size;
  if (verifier_) {
    const auto opened = verifier_->open(channel, data, size);
    if (!opened.authentic) return refuse(channel, "unauthenticated: " + opened.reason);
    payload = opened.payload_size;
  }
  heartbeat_t hb;
  if (!bus_auth::decode_payload(hb, data, payload)) return refuse(channel, "undecodable");
  if (const std::string why = validate(hb); !why.empty()) return refuse(channel, why);
  ++heard_;
  return "heartbeat " + channel + " " + std::to_string(hb.pid) + " " + std::to_string(hb.utime);
}

}  // namespace ofn::report
