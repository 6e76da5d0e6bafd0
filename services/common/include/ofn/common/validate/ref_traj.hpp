#pragma once
// The content check of ref_traj_t (REF_TRAJ): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/ref_traj_t.hpp"

namespace ofn {

std::string validate(const ref_traj_t& msg);

}  // namespace ofn
