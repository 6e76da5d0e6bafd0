// Cost of one trajectory-controller step with the adaptive element (two
// single-hidden-layer networks, forward pass and update) and without it, and
// of one disturbed physics step (Dryden turbulence + RK4).

#include <benchmark/benchmark.h>

#include "ofn/controller/neural_adaptation.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"
#include "ofn/vehicle_sim/disturbances.hpp"

namespace {

using ofn::Vec3;

void controller_step(benchmark::State& state, bool adaptive) {
  ofn::control::AdaptiveConfig config;
  config.enabled = adaptive;
  ofn::control::TrajectoryController controller{
      ofn::vehicle::RotorcraftParams{}, {}, ofn::control::make_adaptive_element(config)};
  ofn::control::Reference ref;
  ref.position = Vec3(5, 1, -30);
  ref.velocity = Vec3(3, 0, 0);
  ofn::control::VehicleEstimate x;
  x.position = Vec3(0, 0, -30);
  x.velocity = Vec3(2.9, 0.1, 0);
  x.attitude = ofn::quat_from_euler(0.02, -0.05, 0.0);
  x.body_rates = Vec3(0.01, -0.02, 0.03);
  for (auto _ : state) benchmark::DoNotOptimize(controller.step(ref, x, 0.01));
}

void BM_ControllerStepAdaptive(benchmark::State& state) {
  controller_step(state, true);
}
BENCHMARK(BM_ControllerStepAdaptive);

void BM_ControllerStepNonAdaptive(benchmark::State& state) {
  controller_step(state, false);
}
BENCHMARK(BM_ControllerStepNonAdaptive);

void BM_DisturbedPhysicsStep(benchmark::State& state) {
  ofn::Disturbances d;
  d.turbulence.wind_at_20ft = 30 * 1852.0 / 3600.0;
  d.nav.position_sigma = 0.1;
  d.nav.latency = 0.02;
  ofn::vehicle::SimulatedVehicle v(ofn::vehicle::RotorcraftParams{}, Vec3(0, 7.7, 0), d);
  const auto trim = ofn::vehicle::trim(v.model(), Vec3(3, 0, 0), 0.0, Vec3(0, 7.7, 0));
  auto s = trim.state;
  s.position = Vec3(0, 0, -36);
  v.reset(s, 0.0);
  v.set_command(trim.controls);
  for (auto _ : state) {
    v.step(1.0 / 400.0);
    benchmark::DoNotOptimize(v.measure());
    // Keep the state near the start so the work per step stays typical.
    if (v.time() > 1.0) v.reset(s, 0.0);
  }
}
BENCHMARK(BM_DisturbedPhysicsStep);

}  // namespace
