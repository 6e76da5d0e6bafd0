#include "ofn/rh_optimizer/start_state.hpp"

#include <algorithm>

namespace ofn::rh {

StartState choose_start_state(const BsplineTrajectory& last_plan, LastPlan last_kind,
                              double since_plan, const MeasuredState& measured, double max_accel,
                              const StartStateSettings& settings) {
  StartState start;
  start.position = measured.position;
  start.velocity = measured.velocity;
  const bool stop = last_kind == LastPlan::kStop && settings.stop_recapture_error > 0;
  const bool covers_now =
      !last_plan.empty() && since_plan >= 0 && (stop || since_plan <= last_plan.duration());
  // A stop past its end is its rest point (the spline's end is evaluated there).
  const double at = stop ? std::min(since_plan, last_plan.duration()) : since_plan;
  if (settings.planned_initial_state && covers_now) {
    const Vec3 planned_position = last_plan.position(at);
    const Vec3 planned_velocity = last_plan.velocity(at);
    const double position_error = (planned_position - measured.position).norm();
    const bool near_plan =
        stop ? position_error <= settings.stop_recapture_error
             : position_error <= settings.replan_position_error &&
                   (planned_velocity - measured.velocity).norm() <= settings.replan_velocity_error;
    if (near_plan) {
      start.position = planned_position;
      start.velocity = planned_velocity;
      start.acceleration = last_plan.acceleration(at);
      start.from_plan = true;
      return start;
    }
  }
  if (settings.planned_initial_acceleration) {
    start.acceleration = covers_now ? last_plan.acceleration(at) : Vec3(Vec3::Zero());
  } else {
    start.acceleration = measured.acceleration;
    const double norm = start.acceleration.norm();
    if (norm > max_accel) start.acceleration *= max_accel / norm;
  }
  return start;
}

}  // namespace ofn::rh
