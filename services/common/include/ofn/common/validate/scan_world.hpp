#pragma once
// The content check of scan_world_t (SCAN_WORLD): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/scan_world_t.hpp"

namespace ofn {

std::string validate(const scan_world_t& msg);

}  // namespace ofn
