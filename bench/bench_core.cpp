// Step costs of the flight-critical cores: the 6-DOF dynamics (one RK4
// step), the trim solver, and one controller step (outer + inner loop with
// the model inversion).

#include <benchmark/benchmark.h>

#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/controller/waypoint_guidance.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

namespace {

using ofn::Vec3;

void BM_DynamicsStep(benchmark::State& state) {
  ofn::vehicle::RotorcraftSimulation model;
  const auto trim = ofn::vehicle::trim(model, Vec3(3.0, 0, 0), 0.0);
  model.set_state(trim.state);
  model.set_command(trim.controls);
  for (auto _ : state) {
    model.step(1.0 / 400.0);
    benchmark::DoNotOptimize(model.state());
  }
}
BENCHMARK(BM_DynamicsStep);

void BM_Trim(benchmark::State& state) {
  ofn::vehicle::RotorcraftModel model;
  for (auto _ : state) benchmark::DoNotOptimize(ofn::vehicle::trim(model, Vec3(3.0, 0, 0), 0.0));
}
BENCHMARK(BM_Trim)->Unit(benchmark::kMicrosecond);

void BM_ControllerStep(benchmark::State& state) {
  ofn::control::TrajectoryController controller{ofn::vehicle::RotorcraftParams{}};
  ofn::control::Reference ref;
  ref.position = Vec3(5, 1, -30);
  ref.velocity = Vec3(3, 0, 0);
  ofn::control::VehicleEstimate x;
  x.position = Vec3(0, 0, -30);
  x.velocity = Vec3(2.9, 0.1, 0);
  for (auto _ : state) benchmark::DoNotOptimize(controller.step(ref, x, 0.01));
}
BENCHMARK(BM_ControllerStep);

void BM_GuidanceUpdate(benchmark::State& state) {
  ofn::control::WaypointGuidance guidance;
  ofn::Limits limits{3.048, 0.488, 1.5, 0, 6.1, 61};
  guidance.set_mission({{Vec3(0, 0, -30), 3}, {Vec3(1e6, 0, -30), 3}}, 3.048, limits,
                       Vec3(0, 0, -30), Vec3::Zero());
  Vec3 p(0, 0, -30);
  for (auto _ : state) {
    const auto r = guidance.update(p, Vec3(3, 0, 0), 0.01);
    p = r.position;
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_GuidanceUpdate);

}  // namespace

BENCHMARK_MAIN();
