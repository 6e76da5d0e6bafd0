#pragma once
// The content check of control_status_t (CONTROL_STATUS): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/control_status_t.hpp"

namespace ofn {

std::string validate(const control_status_t& msg);

}  // namespace ofn
