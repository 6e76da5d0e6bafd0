#pragma once
// The content check of narrow_passages_t (NARROW_PASSAGES): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/narrow_passages_t.hpp"

namespace ofn {

std::string validate(const narrow_passages_t& msg);

}  // namespace ofn
