#pragma once
// The content check of obstacle_grid_t (OBSTACLE_GRID): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/obstacle_grid_t.hpp"

namespace ofn {

std::string validate(const obstacle_grid_t& msg);

}  // namespace ofn
