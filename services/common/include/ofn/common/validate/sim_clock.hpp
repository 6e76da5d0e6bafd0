#pragma once
// The content check of sim_clock_t (SIM_CLOCK): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/sim_clock_t.hpp"

namespace ofn {

std::string validate(const sim_clock_t& msg);

}  // namespace ofn
