#include "ofn/controller/perception_watch.hpp"

#include <cmath>
#include <sstream>

namespace ofn::control {

void PerceptionWatch::on_status(double stamp, double map_stamp, bool guidance_clear,
                                MissionLeg checked) {
  if (!std::isfinite(stamp) || stamp < status_stamp_) return;
  status_stamp_ = stamp;
  guidance_clear_ = guidance_clear;
  checked_ = checked;
  map_stamp_ = map_stamp > 0 && std::isfinite(map_stamp) ? map_stamp
                                                         : -std::numeric_limits<double>::infinity();
  confirmed_once_ = confirmed_once_ || std::isfinite(map_stamp_);
}

std::optional<std::string> PerceptionWatch::stale(double now, MissionLeg flown) const {
  if (!settings_.enabled) return std::nullopt;
  std::ostringstream why;
  why.precision(3);
  if (!std::isfinite(status_stamp_)) return std::string("no planner status yet");
  if (now - status_stamp_ > settings_.max_status_age) {
    why << "planner silent for " << now - status_stamp_ << " s";
    return why.str();
  }
  if (!std::isfinite(map_stamp_)) return std::string("the planner has no map yet");
  if (now - map_stamp_ > settings_.max_map_age) {
    why << "the planner's map is " << now - map_stamp_ << " s old";
    return why.str();
  }
  if (!guidance_clear_) return std::string("the planner has not cleared the leg");
  if (checked_ != flown) {
    why << "the planner cleared the leg to waypoint " << checked_.waypoint << " of mission "
        << checked_.mission_id << ", guidance flies to waypoint " << flown.waypoint
        << " of mission " << flown.mission_id;
    return why.str();
  }
  return std::nullopt;
}

}  // namespace ofn::control
