#pragma once
// The content check of mission_t (MISSION): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/mission_t.hpp"

namespace ofn {

std::string validate(const mission_t& msg);

}  // namespace ofn
