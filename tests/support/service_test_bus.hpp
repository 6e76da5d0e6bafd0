#pragma once
// An in-process bus for testing one service: memq:// transport, a manual
// clock, and the service's timers fired in order as the clock advances.

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/node.hpp"
#include "ofn/mission_t.hpp"

namespace ofn::testing_support {

class ServiceTestBus {
 public:
  explicit ServiceTestBus(Utime start) : lcm_("memq://"), clock_(start) {}

  lcm::LCM& lcm() { return lcm_; }
  ManualClock& clock() { return clock_; }
  Utime now() const { return clock_.now(); }

  /// Hands every queued message to its subscribers.
  void deliver() {
    while (lcm_.handleTimeout(0) > 0) {
    }
  }

  /// Moves the clock to t, firing the node's timers on the way (timers are
  /// scheduled by their first firing) and delivering what they publish.
  void advance_to(Node& node, Utime t) { advance_to({&node}, t); }

  /// The same for a service and the test's own nodes (a stand-in
  /// publisher, a recorder): at each step the clock moves to the earliest
  /// deadline among them, every node fires the timers then due, and what
  /// they publish is delivered before time moves on.
  void advance_to(std::initializer_list<Node*> nodes, Utime t) {
    while (true) {
      Utime next = INT64_MAX;
      for (const Node* n : nodes) next = std::min(next, n->next_deadline());
      if (next != INT64_MIN && next > t) break;
      clock_.set(std::max(clock_.now(), next));
      for (Node* n : nodes) n->fire_due_timers();
      deliver();
    }
    clock_.set(t);
    deliver();
  }

  template <class Msg>
  void send(const std::string& channel, const Msg& m) {
    lcm_.publish(channel, &m);
    deliver();
  }

 private:
  lcm::LCM lcm_;
  ManualClock clock_;
};

/// The benchmark courses' plan in SI: one leg north from -100 ft to 500 ft
/// at 120 ft, 10 ft/s, 1.6 ft/s^2, R_s 20 ft, sensor range 200 ft.
inline mission_t course_mission(Utime utime) {
  mission_t m{};
  m.utime = utime;
  m.mission_id = 1;
  m.name = "course";
  m.frame = "NED";
  m.cruise_speed = 3.048;
  m.limits.max_speed = 3.048;
  m.limits.max_accel = 0.48768;
  m.limits.max_vertical_speed = 1.524;
  m.limits.min_forward_speed = 0;
  m.limits.clearance = 6.096;
  m.limits.sensor_range = 60.96;
  for (double north : {-30.48, 152.4}) {
    waypoint_t w{};
    w.position[0] = north;
    w.position[2] = -36.576;
    w.capture_radius = 3.0;
    m.waypoints.push_back(w);
  }
  m.num_waypoints = 2;
  return m;
}

}  // namespace ofn::testing_support
