// Disturbances of the simulated flight: Dryden turbulence statistics and
// its MIL-F-8785C parameters, seeded repeatability, navigation noise and
// latency, airframe variation and actuator authority from the scenario.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/vehicle_sim/disturbances.hpp"

namespace ofn::vehicle {
namespace {

const std::string kWindy = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open_windy.yaml";
constexpr double kFt = kMetresPerFoot;

Vec3 sample_std(uint32_t seed, const DrydenParams& p, double airspeed, double duration, double dt) {
  DrydenTurbulence t(seed);
  Vec3 sum = Vec3::Zero(), sum_sq = Vec3::Zero();
  const int n = static_cast<int>(duration / dt);
  for (int i = 0; i < n; ++i) {
    const Vec3 g = t.step(dt, airspeed, p);
    sum += g;
    sum_sq += g.cwiseProduct(g);
  }
  const Vec3 mean = sum / n;
  return (sum_sq / n - mean.cwiseProduct(mean)).cwiseSqrt();
}

TEST(DrydenTurbulence, HasTheIntendedStandardDeviation) {
  DrydenParams p;
  p.sigma = Vec3(2.0, 1.5, 1.0);
  p.scale_length = Vec3(20.0, 20.0, 10.0);
  // 4000 s at 10 m/s: about 2000 correlation times of the slowest channel.
  const Vec3 s = sample_std(3, p, 10.0, 4000.0, 0.01);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i] / p.sigma[i], 1.0, 0.08) << "axis " << i;
}

TEST(DrydenTurbulence, StandardDeviationHoldsAtLowAirspeed) {
  // Hovering: the airspeed floor keeps the field moving; variance unchanged.
  DrydenParams p;
  p.sigma = Vec3(1.0, 1.0, 1.0);
  p.scale_length = Vec3(5.0, 5.0, 5.0);
  const Vec3 s = sample_std(5, p, 0.0, 6000.0, 0.02);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i], 1.0, 0.1) << "axis " << i;
}

TEST(DrydenTurbulence, SameSeedSameGustsOtherSeedOtherGusts) {
  DrydenParams p;
  p.sigma = Vec3(1, 1, 1);
  DrydenTurbulence a(9), b(9), c(10);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const Vec3 ga = a.step(0.0025, 5.0, p), gb = b.step(0.0025, 5.0, p),
               gc = c.step(0.0025, 5.0, p);
    ASSERT_EQ(ga, gb) << "step " << i;  // bit for bit
    differs = differs || ga != gc;
  }
  EXPECT_TRUE(differs);
}

TEST(DrydenTurbulence, LowAltitudeParametersFollowMilF8785C) {
  // At 120 ft, moderate (W20 = 30 kt): sigma_w = 3 kt, L_w = 120 ft.
  const double kt = 1852.0 / 3600.0;
  const DrydenParams p = dryden_low_altitude(120 * kFt, 30 * kt);
  EXPECT_NEAR(p.sigma.z(), 3.0 * kt, 1e-9);
  EXPECT_NEAR(p.scale_length.z(), 120 * kFt, 1e-9);
  const double base = 0.177 + 0.000823 * 120;
  EXPECT_NEAR(p.sigma.x(), 3.0 * kt / std::pow(base, 0.4), 1e-9);
  EXPECT_NEAR(p.sigma.y(), p.sigma.x(), 1e-12);
  EXPECT_NEAR(p.scale_length.x(), 120 / std::pow(base, 1.2) * kFt, 1e-9);
  // Horizontal gusts are stronger and longer than vertical ones near the ground.
  EXPECT_GT(p.sigma.x(), p.sigma.z());
  EXPECT_GT(p.scale_length.x(), p.scale_length.z());
}

TEST(SimulatedVehicle, TurbulentFlightIsRepeatableForASeed) {
  const Scenario s = load_scenario(kWindy);
  auto fly = [&](uint32_t seed) {
    Disturbances d = s.disturbances;
    d.seed = seed;
    SimulatedVehicle v(apply_variation({}, s.vehicle), s.wind, d);
    const auto t = trim(v.model(), s.start_velocity, s.start_heading, s.wind);
    v.reset(t.state, 0);
    v.set_command(t.controls);
    for (int i = 0; i < 4000; ++i) v.step(0.0025);
    return v.model().state().position;
  };
  EXPECT_EQ(fly(4), fly(4));
  EXPECT_NE(fly(4), fly(5));
}

TEST(SimulatedVehicle, NavigationSolutionIsLateByTheLatency) {
  Disturbances d;
  d.nav.latency = 0.05;
  SimulatedVehicle v(RotorcraftParams{}, Vec3::Zero(), d);
  RotorcraftState s;
  s.velocity = Vec3(5, 0, 0);  // not trimmed: only the timing matters
  v.reset(s, 0.0);
  std::vector<std::pair<double, double>> truth;  // time, north
  for (int i = 0; i < 200; ++i) {
    v.step(0.0025);
    truth.emplace_back(v.time(), v.model().state().position.x());
  }
  const NavSample n = v.measure();
  EXPECT_NEAR(v.time() - n.time, 0.05, 1e-6);
  // The reported position is the true one at the reported time.
  const auto& then = truth[truth.size() - 1 - 20];
  EXPECT_NEAR(then.first, n.time, 1e-9);
  EXPECT_DOUBLE_EQ(then.second, n.position.x());
}

TEST(SimulatedVehicle, NavigationNoiseHasTheGivenSpread) {
  Disturbances d;
  d.nav.position_sigma = 0.2;
  d.nav.velocity_sigma = 0.05;
  d.nav.attitude_sigma = deg2rad(0.5);
  SimulatedVehicle v(RotorcraftParams{}, Vec3::Zero(), d);
  v.reset(RotorcraftState{}, 0.0);
  double pos_sq = 0, vel_sq = 0, att_sq = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const NavSample m = v.measure();
    pos_sq += m.position.squaredNorm();
    vel_sq += m.velocity.squaredNorm();
    att_sq += std::pow(Eigen::AngleAxisd(m.attitude).angle(), 2);
  }
  EXPECT_NEAR(std::sqrt(pos_sq / (3 * n)), 0.2, 0.01);
  EXPECT_NEAR(std::sqrt(vel_sq / (3 * n)), 0.05, 0.0025);
  EXPECT_NEAR(std::sqrt(att_sq / (3 * n)), deg2rad(0.5), deg2rad(0.03));
}

TEST(SimulatedVehicle, NoDisturbancesMeansTheTrueStateNow) {
  SimulatedVehicle v(RotorcraftParams{}, Vec3::Zero(), Disturbances{});
  RotorcraftState s;
  s.position = Vec3(1, 2, -3);
  v.reset(s, 0.0);
  v.step(0.0025);
  const NavSample n = v.measure();
  EXPECT_EQ(n.position, v.model().state().position);
  EXPECT_EQ(n.time, v.time());
}

TEST(VehicleVariation, ScalesTheAirframeAndSetsActuatorAuthority) {
  VehicleVariation var;
  var.mass_scale = 1.2;
  var.inertia_scale = Vec3(1.5, 1.0, 0.8);
  var.actuator_time_scale = 2.0;
  var.cyclic_limit = deg2rad(5.0);
  var.collective_rate = 0.5;
  const RotorcraftParams base;
  const RotorcraftParams p = apply_variation(base, var);
  EXPECT_DOUBLE_EQ(p.mass, 1.2 * base.mass);
  EXPECT_DOUBLE_EQ(p.inertia.x(), 1.5 * base.inertia.x());
  EXPECT_DOUBLE_EQ(p.inertia.z(), 0.8 * base.inertia.z());
  EXPECT_DOUBLE_EQ(p.servo_time_constant, 2.0 * base.servo_time_constant);
  EXPECT_DOUBLE_EQ(p.max_controls.lon_cyclic, deg2rad(5.0));
  EXPECT_DOUBLE_EQ(p.min_controls.lat_cyclic, -deg2rad(5.0));
  EXPECT_DOUBLE_EQ(p.actuator_rate.collective, 0.5);
  EXPECT_DOUBLE_EQ(p.actuator_rate.pedal, base.actuator_rate.pedal);
  // The model honours the narrower authority.
  RotorcraftSimulation m(p);
  m.set_command({0.1, 1.0, -1.0, 0.0});
  EXPECT_DOUBLE_EQ(m.command().lon_cyclic, deg2rad(5.0));
  EXPECT_DOUBLE_EQ(m.command().lat_cyclic, -deg2rad(5.0));
}

// Writes a scenario file, loads it and removes it again.
Scenario load_written_scenario(const std::string& name, const std::string& extra) {
  // The process id keeps parallel test processes (and parallel builds) apart.
  const std::string path =
      ::testing::TempDir() + "/ofn_" + name + "_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << "name: " << name
                      << "\nunits: ft\nstart:\n  position: [0, 0, 100]\nwaypoints:\n"
                         "  - position: [100, 0, 100]\nlimits:\n  max_speed: 10\n"
                         "  max_accel: 2\n  max_vertical_speed: 5\n"
                      << extra;
  struct RemoveOnExit {
    const std::string& path;
    ~RemoveOnExit() { std::remove(path.c_str()); }
  } remove_on_exit{path};
  return load_scenario(path);
}

TEST(ScenarioDisturbances, AbsentSectionsAreBenign) {
  const Scenario s = load_written_scenario("plain", "");
  EXPECT_EQ(s.vehicle.mass_scale, 1.0);
  EXPECT_EQ(s.vehicle.inertia_scale, Vec3::Ones());
  EXPECT_FALSE(s.vehicle.cyclic_limit.has_value());
  EXPECT_FALSE(s.disturbances.turbulence.active());
  EXPECT_EQ(s.disturbances.nav.latency, 0.0);
  EXPECT_EQ(s.disturbances.nav.position_sigma, 0.0);
}

TEST(ScenarioDisturbances, ReadsEveryFieldInFileUnits) {
  const Scenario s = load_written_scenario(
      "full",
      "vehicle:\n  mass_scale: 1.3\n  inertia_scale: [1.1, 1.2, 1.3]\n"
      "  actuator_time_scale: 1.5\n  actuator_limits:\n    collective_deg: [-2, 15]\n"
      "    cyclic_deg: 6\n    pedal_deg: 20\n    collective_rate_deg_s: 40\n"
      "    cyclic_rate_deg_s: 50\n    pedal_rate_deg_s: 60\n"
      "disturbances:\n  turbulence_sigma: [3, 2, 1]\n  turbulence_scale: [500, 400, 100]\n"
      "  nav_noise:\n    position: 1\n    velocity: 0.5\n    attitude_deg: 0.3\n"
      "    rate_deg_s: 0.2\n    latency: 0.04\n  seed: 42\n");
  EXPECT_DOUBLE_EQ(s.vehicle.mass_scale, 1.3);
  EXPECT_DOUBLE_EQ(s.vehicle.inertia_scale.y(), 1.2);
  EXPECT_DOUBLE_EQ(*s.vehicle.collective_min, deg2rad(-2));
  EXPECT_DOUBLE_EQ(*s.vehicle.collective_max, deg2rad(15));
  EXPECT_DOUBLE_EQ(*s.vehicle.pedal_rate, deg2rad(60));
  EXPECT_DOUBLE_EQ(s.disturbances.turbulence.sigma->x(), 3 * kFt);
  EXPECT_DOUBLE_EQ(s.disturbances.turbulence.scale_length->z(), 100 * kFt);
  EXPECT_TRUE(s.disturbances.turbulence.active());
  EXPECT_DOUBLE_EQ(s.disturbances.nav.position_sigma, kFt);
  EXPECT_DOUBLE_EQ(s.disturbances.nav.latency, 0.04);
  EXPECT_EQ(s.disturbances.seed, 42u);
}

TEST(ScenarioDisturbances, MistakesNameTheField) {
  auto error_of = [](const std::string& extra) {
    try {
      load_written_scenario("bad", extra);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("disturbances:\n  turbulence: stormy\n").find("disturbances.turbulence"),
            std::string::npos);
  EXPECT_NE(error_of("vehicle:\n  mass_scal: 1.2\n").find("mass_scal"), std::string::npos);
  EXPECT_NE(error_of("disturbances:\n  turbulence: light\n  turbulence_sigma: [1, 1, 1]\n")
                .find("turbulence_sigma"),
            std::string::npos);
  EXPECT_NE(error_of("vehicle:\n  actuator_limits:\n    collective_deg: [10, 5]\n")
                .find("collective_deg"),
            std::string::npos);
}

}  // namespace
}  // namespace ofn::vehicle
