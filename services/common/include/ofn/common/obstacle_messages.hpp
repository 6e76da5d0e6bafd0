#pragma once
// Conversions between the scenario's obstacle description and obstacle_t,
// the form VIRTUAL_OBSTACLES carries on the bus.

#include "ofn/common/scenario.hpp"
#include "ofn/obstacle_t.hpp"

namespace ofn {

inline obstacle_t to_message(const ObstacleSpec& s) {
  obstacle_t m{};
  m.id = s.id;
  m.kind = s.kind == ObstacleSpec::Kind::kBox        ? obstacle_t::BOX
           : s.kind == ObstacleSpec::Kind::kCylinder ? obstacle_t::CYLINDER
                                                     : obstacle_t::TREE;
  m.center[0] = s.north;
  m.center[1] = s.east;
  m.size[0] = s.length;
  m.size[1] = s.width;
  m.height = s.height;
  m.yaw = s.yaw;
  m.seed = s.seed;
  m.appear_time = s.appear_time;
  m.disappear_time = s.disappear_time;
  return m;
}

/// The message must have passed validate(virtual_obstacles_t).
inline ObstacleSpec from_message(const obstacle_t& m) {
  ObstacleSpec s;
  s.id = m.id;
  s.kind = m.kind == obstacle_t::BOX        ? ObstacleSpec::Kind::kBox
           : m.kind == obstacle_t::CYLINDER ? ObstacleSpec::Kind::kCylinder
                                            : ObstacleSpec::Kind::kTree;
  s.north = m.center[0];
  s.east = m.center[1];
  s.length = m.size[0];
  s.width = m.size[1];
  s.height = m.height;
  s.yaw = m.yaw;
  s.seed = m.seed;
  s.appear_time = m.appear_time;
  s.disappear_time = m.disappear_time;
  return s;
}

}  // namespace ofn
