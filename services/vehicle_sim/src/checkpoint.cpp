#include "ofn/vehicle_sim/checkpoint.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace ofn::vehicle {
namespace {

constexpr const char* kMagic = "ofn_vehicle_checkpoint";
constexpr int kVersion = 1;

std::string numbers(std::initializer_list<double> values) {
  std::ostringstream out;
  out.precision(17);
  const char* sep = "";
  for (double v : values) {
    out << sep << v;
    sep = " ";
  }
  return out.str();
}

[[noreturn]] void fail(int line, const std::string& what) {
  throw std::runtime_error("vehicle checkpoint, line " + std::to_string(line) + ": " + what);
}

}  // namespace

std::string checkpoint_to_text(const VehicleCheckpoint& c) {
  const RotorcraftState& s = c.state;
  std::ostringstream out;
  out << kMagic << ' ' << kVersion << '\n'
      << "time_us " << c.time_us << '\n'
      << "steps " << c.steps << '\n'
      << "released " << (c.released ? 1 : 0) << '\n'
      << "position " << numbers({s.position.x(), s.position.y(), s.position.z()}) << '\n'
      << "velocity " << numbers({s.velocity.x(), s.velocity.y(), s.velocity.z()}) << '\n'
      << "attitude " << numbers({s.attitude.w(), s.attitude.x(), s.attitude.y(), s.attitude.z()})
      << '\n'
      << "body_rates " << numbers({s.body_rates.x(), s.body_rates.y(), s.body_rates.z()}) << '\n'
      << "flapping " << numbers({s.flap_lon, s.flap_lat}) << '\n'
      << "induced_velocity " << numbers({s.induced_velocity}) << '\n'
      << "actuators "
      << numbers({s.actuators.collective, s.actuators.lon_cyclic, s.actuators.lat_cyclic,
                  s.actuators.pedal})
      << '\n';
  return out.str();
}

VehicleCheckpoint checkpoint_from_text(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  int line_number = 1;
  if (!std::getline(in, line)) fail(line_number, "empty");
  {
    std::istringstream head(line);
    std::string magic;
    int version = 0;
    if (!(head >> magic >> version) || magic != kMagic)
      fail(line_number, std::string("not a vehicle checkpoint (expected '") + kMagic + " " +
                            std::to_string(kVersion) + "')");
    if (version != kVersion)
      fail(line_number, "format version " + std::to_string(version) + ", this build reads " +
                            std::to_string(kVersion));
  }

  VehicleCheckpoint c;
  RotorcraftState& s = c.state;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  double released = 0;
  // Each key: how many numbers, and where they go.
  struct Field {
    size_t count;
    std::function<void(const std::vector<double>&)> take;
  };
  const std::map<std::string, Field> fields = {
      {"time_us", {1, [&](const auto& v) { c.time_us = static_cast<int64_t>(v[0]); }}},
      {"steps", {1, [&](const auto& v) { c.steps = static_cast<int64_t>(v[0]); }}},
      {"released", {1, [&](const auto& v) { released = v[0]; }}},
      {"position", {3, [&](const auto& v) { s.position = Vec3(v[0], v[1], v[2]); }}},
      {"velocity", {3, [&](const auto& v) { s.velocity = Vec3(v[0], v[1], v[2]); }}},
      {"attitude", {4, [&](const auto& v) { q = Eigen::Vector4d(v[0], v[1], v[2], v[3]); }}},
      {"body_rates", {3, [&](const auto& v) { s.body_rates = Vec3(v[0], v[1], v[2]); }}},
      {"flapping",
       {2,
        [&](const auto& v) {
          s.flap_lon = v[0];
          s.flap_lat = v[1];
        }}},
      {"induced_velocity", {1, [&](const auto& v) { s.induced_velocity = v[0]; }}},
      {"actuators",
       {4,
        [&](const auto& v) {
          s.actuators = Controls{v[0], v[1], v[2], v[3]};
        }}},
  };
  std::map<std::string, bool> seen;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;  // a blank line
    const auto field = fields.find(key);
    if (field == fields.end()) fail(line_number, "unknown key '" + key + "'");
    if (seen[key]) fail(line_number, "'" + key + "' given twice");
    seen[key] = true;
    std::vector<double> values;
    std::string word;
    while (words >> word) {
      size_t used = 0;
      double value = 0;
      try {
        value = std::stod(word, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size() || !std::isfinite(value))
        fail(line_number, "'" + key + "': '" + word + "' is not a finite number");
      values.push_back(value);
    }
    if (values.size() != field->second.count)
      fail(line_number, "'" + key + "' takes " + std::to_string(field->second.count) +
                            " number(s), got " + std::to_string(values.size()));
    field->second.take(values);
  }
  std::string missing;
  for (const auto& [key, field] : fields)
    if (!seen[key]) missing += (missing.empty() ? "'" : ", '") + key + "'";
  if (!missing.empty()) fail(line_number, "cut short: " + missing + " missing");
  if (c.time_us < 0 || c.steps < 0) fail(line_number, "negative time_us or steps");
  if (released != 0 && released != 1) fail(line_number, "'released' is 0 or 1");
  c.released = released == 1;
  // A saved unit quaternion reads back within rounding; anything else is
  // not an attitude.
  if (std::abs(q.norm() - 1.0) > 1e-6) fail(line_number, "'attitude' is not a unit quaternion");
  s.attitude = Quat(q[0], q[1], q[2], q[3]).normalized();
  return c;
}

void write_checkpoint_file(const std::string& path, const VehicleCheckpoint& checkpoint) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << checkpoint_to_text(checkpoint);
    out.flush();
    if (!out) throw std::runtime_error("cannot write the vehicle checkpoint " + temporary);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename " + temporary + " to " + path);
}

std::optional<VehicleCheckpoint> read_checkpoint_file(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error) && !error) return std::nullopt;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the vehicle checkpoint " + path);
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return checkpoint_from_text(text.str());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace ofn::vehicle
