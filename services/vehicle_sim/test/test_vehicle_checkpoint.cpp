// The simulated aircraft's checkpoint: what a restarted vehicle_sim resumes
// from. It must read back exactly what was saved, and refuse a file that is
// not a whole checkpoint with a message that says what is wrong where.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "ofn/vehicle_sim/checkpoint.hpp"

namespace ofn::vehicle {
namespace {

VehicleCheckpoint a_flight() {
  VehicleCheckpoint c;
  c.time_us = 41'230'000;
  c.steps = 16'492;
  c.released = true;
  RotorcraftState& s = c.state;
  s.position = Vec3(12.345678901234567, -3.25, -36.576);
  s.velocity = Vec3(3.0123, 0.1, -0.05);
  s.attitude = Quat(Eigen::AngleAxisd(0.3, Vec3(0.1, 0.2, 1.0).normalized()));
  s.body_rates = Vec3(0.01, -0.02, 0.3);
  s.flap_lon = 0.012;
  s.flap_lat = -0.004;
  s.induced_velocity = 6.1;
  s.actuators = Controls{0.11, -0.02, 0.003, 0.07};
  return c;
}

std::string replace_line(const std::string& text, const std::string& key, const std::string& line) {
  const size_t at = text.find("\n" + key + " ");
  EXPECT_NE(at, std::string::npos) << key;
  const size_t end = text.find('\n', at + 1);
  return text.substr(0, at + 1) + line + text.substr(end);
}

std::string error_of(const std::string& text) {
  try {
    checkpoint_from_text(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(VehicleCheckpoint, ReadsBackExactlyWhatWasSaved) {
  const VehicleCheckpoint saved = a_flight();
  const VehicleCheckpoint read = checkpoint_from_text(checkpoint_to_text(saved));
  EXPECT_EQ(read.time_us, saved.time_us);
  EXPECT_EQ(read.steps, saved.steps);
  EXPECT_EQ(read.released, saved.released);
  EXPECT_EQ(read.state.position, saved.state.position);
  EXPECT_EQ(read.state.velocity, saved.state.velocity);
  EXPECT_NEAR(read.state.attitude.angularDistance(saved.state.attitude), 0.0, 1e-12);
  EXPECT_EQ(read.state.body_rates, saved.state.body_rates);
  EXPECT_EQ(read.state.flap_lon, saved.state.flap_lon);
  EXPECT_EQ(read.state.flap_lat, saved.state.flap_lat);
  EXPECT_EQ(read.state.induced_velocity, saved.state.induced_velocity);
  EXPECT_EQ(read.state.actuators.as_array(), saved.state.actuators.as_array());
}

TEST(VehicleCheckpoint, RefusesWhatIsNotAWholeCheckpoint) {
  const std::string good = checkpoint_to_text(a_flight());
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_NE(error_of("position 1 2 3\n").find("not a vehicle checkpoint"), std::string::npos);
  EXPECT_NE(error_of("ofn_vehicle_checkpoint 2\n").find("format version 2"), std::string::npos);
  // Cut short (the body of a crash mid-write, were it not renamed into place).
  EXPECT_NE(error_of(good.substr(0, good.find("\nflapping")))
                .find("'actuators', 'flapping', 'induced_velocity' missing"),
            std::string::npos);
  EXPECT_NE(error_of(replace_line(good, "velocity", "velocity 1 nan 0")).find("line 6"),
            std::string::npos);
  EXPECT_NE(error_of(replace_line(good, "velocity", "velocity 1 inf 0")).find("not a finite"),
            std::string::npos);
  EXPECT_NE(error_of(replace_line(good, "position", "position 1 2")).find("takes 3"),
            std::string::npos);
  EXPECT_NE(error_of(replace_line(good, "attitude", "attitude 1 1 0 0")).find("unit quaternion"),
            std::string::npos);
  EXPECT_NE(error_of(good + "steps 3\n").find("given twice"), std::string::npos);
  EXPECT_NE(error_of(good + "rotor_speed 3\n").find("unknown key 'rotor_speed'"),
            std::string::npos);
  EXPECT_NE(error_of(replace_line(good, "released", "released 2")).find("0 or 1"),
            std::string::npos);
}

TEST(VehicleCheckpoint, AFileIsWrittenWholeAndAMissingOneIsNoCheckpoint) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "ofn_test_vehicle.checkpoint").string();
  std::remove(path.c_str());
  EXPECT_FALSE(read_checkpoint_file(path).has_value());
  write_checkpoint_file(path, a_flight());
  const auto read = read_checkpoint_file(path);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->time_us, a_flight().time_us);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  // A damaged file is an error that names it, not a fresh start.
  std::ofstream(path) << "garbage\n";
  try {
    read_checkpoint_file(path);
    ADD_FAILURE() << "a damaged checkpoint was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace ofn::vehicle
