#include "ofn/rh_optimizer/start_state.hpp"

namespace ofn::rh {

StartState choose_start_state(const BsplineTrajectory& last_plan, double since_plan,
                              const MeasuredState& measured, double max_accel,
                              const StartStateSettings& settings) {
  StartState start;
  start.position = measured.position;
  start.velocity = measured.velocity;
  const bool covers_now =
      !last_plan.empty() && since_plan >= 0 && since_plan <= last_plan.duration();
  if (settings.planned_initial_state && covers_now) {
    const Vec3 planned_position = last_plan.position(since_plan);
    const Vec3 planned_velocity = last_plan.velocity(since_plan);
    if ((planned_position - measured.position).norm() <= settings.replan_position_error &&
        (planned_velocity - measured.velocity).norm() <= settings.replan_velocity_error) {
      start.position = planned_position;
      start.velocity = planned_velocity;
      start.acceleration = last_plan.acceleration(since_plan);
      start.from_plan = true;
      return start;
    }
  }
  if (settings.planned_initial_acceleration) {
    start.acceleration = covers_now ? last_plan.acceleration(since_plan) : Vec3(Vec3::Zero());
  } else {
    start.acceleration = measured.acceleration;
    const double norm = start.acceleration.norm();
    if (norm > max_accel) start.acceleration *= max_accel / norm;
  }
  return start;
}

}  // namespace ofn::rh
