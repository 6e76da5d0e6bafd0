#pragma once
// The content check of solver_stats_t (SOLVER_STATS): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/solver_stats_t.hpp"

namespace ofn {

std::string validate(const solver_stats_t& msg);

}  // namespace ofn
