#pragma once
// The content check of scanner_status_t (SCANNER_STATUS): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/scanner_status_t.hpp"

namespace ofn {

std::string validate(const scanner_status_t& msg);

}  // namespace ofn
