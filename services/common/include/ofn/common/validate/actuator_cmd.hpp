#pragma once
// The content check of actuator_cmd_t (ACTUATOR_CMD): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/actuator_cmd_t.hpp"

namespace ofn {

std::string validate(const actuator_cmd_t& msg);

}  // namespace ofn
