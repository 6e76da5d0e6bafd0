#pragma once
// The content check of heartbeat_t (HEARTBEAT_<NAME>): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/heartbeat_t.hpp"

namespace ofn {

std::string validate(const heartbeat_t& msg);

}  // namespace ofn
