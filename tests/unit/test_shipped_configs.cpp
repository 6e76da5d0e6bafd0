// The shipped config files agree with each other where one service relies
// on another's settings: the controller's nominal airframe is the one
// vehicle_sim flies, and the RH optimiser's commit window covers what the
// controller flies of a plan alone. Each needs two services' readers.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace ofn {
namespace {

/// Every parameter of an airframe, in one list, to compare two bit for bit.
std::vector<double> every_parameter(const vehicle::RotorcraftParams& p) {
  std::vector<double> v = {
      p.mass,           p.inertia.x(),         p.inertia.y(),           p.inertia.z(),
      p.air_density,    p.rotor_radius,        p.rotor_speed,           p.lift_slope,
      p.solidity,       p.profile_drag,        p.inflow_time_constant,  p.hub_height,
      p.flap_stiffness, p.flap_time_constant,  p.cyclic_to_flap,        p.flap_blowback,
      p.tail_arm,       p.tail_thrust_per_rad, p.tail_velocity_damping, p.drag_area.x(),
      p.drag_area.y(),  p.drag_area.z(),       p.servo_time_constant};
  for (const vehicle::Controls* c : {&p.min_controls, &p.max_controls, &p.actuator_rate})
    for (double x : c->as_array()) v.push_back(x);
  return v;
}

TEST(ControllerConfig, ShippedNominalAirframeIsTheShippedSimulatedOne) {
  // The controller's model is exact until a scenario varies the airframe,
  // as it was when the model was the simulator's own.
  auto controller_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/controller.yaml");
  auto sim_reader = YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/vehicle_sim.yaml");
  const auto nominal = control::load_controller_config(controller_reader).nominal;
  const auto flown = vehicle::load_vehicle_sim_config(sim_reader).params;
  EXPECT_EQ(every_parameter(nominal), every_parameter(flown));
  EXPECT_EQ(every_parameter(nominal), every_parameter(vehicle::RotorcraftParams{}));
  auto empty = YamlReader::empty("(defaults)");
  EXPECT_EQ(every_parameter(control::load_controller_config(empty).nominal),
            every_parameter(vehicle::RotorcraftParams{}));
}

TEST(RhOptimizerConfig, ShippedCommitWindowCoversWhatTheControllerFliesAlone) {
  // The controller flies a plan until ref_traj_timeout after its stamp and
  // then that plan's stop; the optimiser checks the stop from every instant
  // of commit_time after the stamp. The window must hold the timeout, one
  // control period, and the lag of the controller's clock behind the
  // optimiser's (two SIM_CLOCK followers over a delayed link).
  auto controller_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/controller.yaml");
  auto optimiser_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/rh_optimizer.yaml");
  const auto controller = control::load_controller_config(controller_reader);
  const auto optimiser = rh::load_rh_optimizer_config(optimiser_reader);
  const double control_period = 1.0 / controller.rate;
  constexpr double kClockLag = 0.1;  // s
  EXPECT_GE(optimiser.commit.commit_time, controller.ref_traj_timeout + control_period + kClockLag);
}

}  // namespace
}  // namespace ofn
