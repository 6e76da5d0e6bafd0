#pragma once
// The content check of cuboid_list_t (CUBOIDS): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/cuboid_list_t.hpp"

namespace ofn {

std::string validate(const cuboid_list_t& msg);

}  // namespace ofn
