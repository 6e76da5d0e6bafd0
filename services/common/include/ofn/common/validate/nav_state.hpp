#pragma once
// The content check of nav_state_t (NAV_STATE): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/nav_state_t.hpp"

namespace ofn {

std::string validate(const nav_state_t& msg);

}  // namespace ofn
