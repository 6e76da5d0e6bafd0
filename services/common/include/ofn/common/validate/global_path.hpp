#pragma once
// The content check of global_path_t (GLOBAL_PATH): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/global_path_t.hpp"

namespace ofn {

std::string validate(const global_path_t& msg);

}  // namespace ofn
