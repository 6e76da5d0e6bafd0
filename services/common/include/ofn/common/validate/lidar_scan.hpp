#pragma once
// The content check of lidar_scan_t (LIDAR_RAW): an empty string when acceptable, else a
// short reason the node counts and logs (ofn/common/message_checks.hpp).

#include <string>

#include "ofn/lidar_scan_t.hpp"

namespace ofn {

std::string validate(const lidar_scan_t& msg);

}  // namespace ofn
