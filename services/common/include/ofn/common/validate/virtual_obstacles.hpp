#pragma once
// The content check of virtual_obstacles_t (VIRTUAL_OBSTACLES): an empty string when acceptable,
// else a short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/virtual_obstacles_t.hpp"

namespace ofn {

std::string validate(const virtual_obstacles_t& msg);

}  // namespace ofn
