// The RH optimiser's decisions without a bus: what a tick publishes (nothing,
// SOLVER_STATS alone, NOMINAL, a hover, a step) and as what, from plain
// navigation, map and route inputs.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/avoidance_supervisor.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

using testing_support::Box;
using testing_support::heightfield_with;
using testing_support::kBenchmarkLimits;
using testing_support::kLegAltitude;
using testing_support::untimed;
using Publish = SupervisorDecision::Publish;

constexpr int kMission = 3;
constexpr double kSpeed = 3.048;        // m/s, the benchmarks' speed limit
constexpr Utime kTick = 100000;         // us, 10 Hz
constexpr Utime kStart = 10 * 1000000;  // us

/// A wall across the whole map, `top` m tall, its near face `north` m north.
Box wall_across(int north, float top = 300.0f) {
  return Box{north, north + 3, -60, 60, top};
}

bool logged(const SupervisorDecision& d, const std::string& part) {
  for (const LogLine& line : d.log)
    if (line.text.find(part) != std::string::npos) return true;
  return false;
}

class AvoidanceSupervisorTest : public ::testing::Test {
 protected:
  static SupervisorSettings settings() {
    SupervisorSettings s;
    s.optimizer = untimed();
    s.optimizer.clearance_margin = 0.5;
    return s;
  }

  explicit AvoidanceSupervisorTest(SupervisorSettings s = settings()) : supervisor_(s) { map({}); }

  void start() {
    // North along the leg from the origin to 150 m, level.
    supervisor_.start_mission(
        kMission, {{Vec3(0, 0, -kLegAltitude), 5.0}, {Vec3(150, 0, -kLegAltitude), 5.0}},
        kBenchmarkLimits);
  }

  /// The map the next ticks decide on.
  void map(const std::vector<Box>& boxes) {
    heightfield_ = std::make_shared<mapping::Heightfield>(heightfield_with(boxes));
    field_ = std::make_shared<mapping::DistanceField>();
    field_->build(*heightfield_, 0.0, 80.0);
  }

  /// One tick at now_ with navigation `position`, `velocity`, `yaw` stamped
  /// now and a grid `grid_age` old (none if negative); then the clock moves
  /// on by a tick.
  SupervisorDecision tick(const Vec3& position, const Vec3& velocity = Vec3(kSpeed, 0, 0),
                          double yaw = 0.0, double grid_age = 0.0) {
    TickInput in;
    in.now = now_;
    NavInput nav;
    nav.utime = now_;
    nav.position = position;
    nav.velocity = velocity;
    nav.yaw = yaw;
    in.nav = nav;
    if (grid_age >= 0) in.grid_utime = now_ - to_utime(grid_age);
    in.map = [this] {
      ++map_requests_;
      MapView view;
      view.heightfield = heightfield_.get();
      auto field = field_;
      view.clearance = [field](const Vec3& p) { return field->query(p); };
      return view;
    };
    const SupervisorDecision d = supervisor_.tick(in);
    now_ += kTick;
    return d;
  }

  /// A route as the global planner publishes it, stamped now.
  void route(RouteKind kind, const std::vector<Vec3>& points) {
    RouteInput r;
    r.utime = now_;
    r.kind = kind;
    r.points = points;
    r.guess = kind == RouteKind::kForward && points.size() >= 2;
    supervisor_.route(r, points.empty() ? std::nullopt : std::optional<Vec3>(points.front()));
  }

  AvoidanceSupervisor supervisor_;
  std::shared_ptr<mapping::Heightfield> heightfield_;
  std::shared_ptr<mapping::DistanceField> field_;
  Utime now_ = kStart;
  int map_requests_ = 0;
};

const Vec3 kOnLeg(0, 0, -kLegAltitude);

TEST_F(AvoidanceSupervisorTest, NothingBeforeAMissionAndNavigation) {
  SupervisorDecision d = tick(kOnLeg);
  EXPECT_EQ(d.publish, Publish::kNothing);
  EXPECT_EQ(d.state, "waiting for mission and nav");
  start();
  TickInput no_nav;
  no_nav.now = now_;
  d = supervisor_.tick(no_nav);
  EXPECT_EQ(d.publish, Publish::kNothing);
  EXPECT_EQ(map_requests_, 0);
}

TEST_F(AvoidanceSupervisorTest, ClearWayAheadIsNominalGuidanceWithANominalOnceASecond) {
  start();
  std::vector<int> nominal_ticks;
  for (int i = 1; i <= 25; ++i) {
    const SupervisorDecision d = tick(Vec3(kSpeed * 0.1 * i, 0, -kLegAltitude));
    ASSERT_TRUE(d.publish == Publish::kStats || d.publish == Publish::kNominal) << i;
    EXPECT_EQ(d.status, StatsStatus::kNotRun);
    EXPECT_EQ(d.message, "nominal guidance: path clear");
    EXPECT_TRUE(d.guidance_clear);
    if (d.publish == Publish::kNominal) nominal_ticks.push_back(i);
  }
  EXPECT_FALSE(supervisor_.engaged());
  EXPECT_EQ(supervisor_.steps(), 0);
  EXPECT_EQ(nominal_ticks, (std::vector<int>{10, 20}));  // every ceil(rate) ticks
  EXPECT_EQ(supervisor_.active_leg(), 1);
}

TEST_F(AvoidanceSupervisorTest, AConflictEngagesAndPlans) {
  start();
  // A wall 45 m ahead, 12.7 m above the leg: climbed over.
  map({Box{45, 48, -20, 20, static_cast<float>(kLegAltitude + 12.7)}});
  const SupervisorDecision d = tick(kOnLeg);
  EXPECT_TRUE(supervisor_.engaged());
  EXPECT_TRUE(logged(d, "avoidance engages at t=10.00 s"));
  ASSERT_EQ(d.publish, Publish::kStep) << d.message;
  EXPECT_EQ(d.mode, PlanMode::kAvoidance);
  EXPECT_EQ(d.status, StatsStatus::kSolved);
  ASSERT_TRUE(d.report);
  EXPECT_GT(d.report->iterations, 0);
  EXPECT_FALSE(d.guidance_clear);
  EXPECT_FALSE(d.trajectory.empty());
  EXPECT_EQ(d.t0, kStart);
  EXPECT_EQ(supervisor_.steps(), 1);
  EXPECT_EQ(map_requests_, 1);
  // Engaged once: the next tick does not say so again.
  EXPECT_FALSE(logged(tick(kOnLeg), "avoidance engages"));
}

TEST_F(AvoidanceSupervisorTest, HandsBackWithANominalAndThenRepeatsItOnceASecond) {
  start();
  map({Box{45, 48, -20, 20, static_cast<float>(kLegAltitude + 12.7)}});
  ASSERT_EQ(tick(kOnLeg).publish, Publish::kStep);
  ASSERT_TRUE(supervisor_.engaged());
  // The wall is gone and the vehicle is on the leg: after the hold (1 s),
  // one NOMINAL hands back.
  map({});
  int handed_back_at = -1;
  for (int i = 1; i <= 20 && handed_back_at < 0; ++i) {
    const SupervisorDecision d = tick(Vec3(kSpeed * 0.1 * i, 0, -kLegAltitude));
    if (d.publish == Publish::kNominal) {
      EXPECT_TRUE(logged(d, "avoidance hands back to waypoint guidance"));
      EXPECT_TRUE(d.guidance_clear);
      handed_back_at = i;
    } else {
      EXPECT_EQ(d.publish, Publish::kStep) << i;  // still avoiding through the hold
    }
  }
  ASSERT_GT(handed_back_at, 0);
  EXPECT_FALSE(supervisor_.engaged());
  // Then NOMINAL again once a second while guidance flies, and stats alone
  // between.
  int since = 0, repeats = 0;
  for (int i = handed_back_at + 1; i <= handed_back_at + 25; ++i) {
    const SupervisorDecision d = tick(Vec3(kSpeed * 0.1 * i, 0, -kLegAltitude));
    ++since;
    if (d.publish == Publish::kNominal) {
      EXPECT_FALSE(logged(d, "hands back"));
      if (repeats > 0) {
        EXPECT_EQ(since, 10);
      }
      since = 0;
      ++repeats;
    } else {
      EXPECT_EQ(d.publish, Publish::kStats);
    }
  }
  EXPECT_GE(repeats, 2);
}

TEST_F(AvoidanceSupervisorTest, ABlindMapOrStaleNavigationGivesStatsAlone) {
  start();
  map({Box{45, 48, -20, 20, static_cast<float>(kLegAltitude + 12.7)}});
  ASSERT_EQ(tick(kOnLeg).publish, Publish::kStep);
  // The grid is older than grid_max_age (1 s), or there is none: an engaged
  // avoidance publishes no plan (the controller flies the last one), and
  // the map is not even brought up to date.
  const int requests = map_requests_;
  for (const double age : {1.2, -1.0}) {
    const SupervisorDecision d = tick(kOnLeg, Vec3(kSpeed, 0, 0), 0.0, age);
    EXPECT_EQ(d.publish, Publish::kStats);
    EXPECT_EQ(d.status, StatsStatus::kNotRun);
    EXPECT_EQ(d.message, "no fresh obstacle grid");
    EXPECT_FALSE(d.guidance_clear);
  }
  EXPECT_EQ(map_requests_, requests);
  EXPECT_TRUE(supervisor_.engaged());
  // A grid exactly grid_max_age old is still fresh.
  EXPECT_EQ(tick(kOnLeg, Vec3(kSpeed, 0, 0), 0.0, 1.0).publish, Publish::kStep);

  // Navigation older than nav_max_age (0.5 s): the same.
  TickInput in;
  in.now = now_;
  NavInput nav;
  nav.utime = now_ - 600000;
  nav.position = kOnLeg;
  in.nav = nav;
  in.grid_utime = now_;
  in.map = [this] {
    ++map_requests_;
    return MapView{};
  };
  const SupervisorDecision stale = supervisor_.tick(in);
  EXPECT_EQ(stale.publish, Publish::kStats);
  EXPECT_EQ(stale.message, "nav stale");
  EXPECT_EQ(map_requests_, requests + 1);
}

TEST_F(AvoidanceSupervisorTest, AMapStarvedOfScansGivesStatsAloneUntilFedAgain) {
  start();
  // Scans at the scanner's 12.5 Hz, then none for more than max_silence (1 s).
  for (int k = 0; k < 20; ++k) supervisor_.scan_received(to_seconds(now_) - 3.0 + 0.08 * k, k);
  SupervisorDecision d = tick(kOnLeg);
  ASSERT_EQ(d.message.rfind("map starved of scans: no scan for ", 0), 0u) << d.message;
  EXPECT_EQ(d.publish, Publish::kStats);
  EXPECT_EQ(d.status, StatsStatus::kNotRun);
  EXPECT_EQ(d.state, "map starved of scans");
  EXPECT_TRUE(logged(d, "no plans until fed again"));
  EXPECT_EQ(map_requests_, 0);
  // Said once; the stats say it at every tick.
  d = tick(kOnLeg);
  EXPECT_EQ(d.publish, Publish::kStats);
  EXPECT_TRUE(d.log.empty());
  // Fed again: decided on the map, and said so.
  for (int k = 20; k < 60; ++k)
    supervisor_.scan_received(to_seconds(now_) - 3.2 + 0.08 * (k - 20), k);
  d = tick(kOnLeg);
  EXPECT_TRUE(logged(d, "map fed again")) << d.message;
  EXPECT_EQ(d.message, "nominal guidance: path clear");
  EXPECT_EQ(map_requests_, 1);
}

// Defers a step that can only brake while nothing has been published and
// the conflict lies beyond the stop plus defer_margin; brakes once a plan or
// a stop has gone out.
class DeferTest : public AvoidanceSupervisorTest {
 protected:
  static SupervisorSettings no_short_retry() {
    SupervisorSettings s = settings();
    s.fallback.short_retry = false;  // a wall across the map: nothing but a stop
    return s;
  }
  DeferTest() : AvoidanceSupervisorTest(no_short_retry()) {}
};

TEST_F(DeferTest, OnlyBeforeAnythingIsPublished) {
  start();
  // 35 m ahead at 3 m/s: the conflict (about 28 m) is farther than the
  // stop (12 m) plus 10 m.
  map({wall_across(35)});
  SupervisorDecision d = tick(kOnLeg);
  EXPECT_TRUE(supervisor_.engaged());
  ASSERT_EQ(d.publish, Publish::kStats) << d.message;
  EXPECT_EQ(d.status, StatsStatus::kDeferred);
  EXPECT_TRUE(d.guidance_clear);
  ASSERT_TRUE(d.report);
  EXPECT_EQ(d.message.rfind("no avoidance trajectory yet (", 0), 0u) << d.message;
  EXPECT_EQ(supervisor_.steps(), 1);
  // 13 m ahead: too near to defer, the stop goes out.
  map({wall_across(13)});
  d = tick(kOnLeg);
  ASSERT_EQ(d.publish, Publish::kStep) << d.message;
  EXPECT_EQ(d.mode, PlanMode::kBraking);
  EXPECT_EQ(d.status, StatsStatus::kBraking);
  // The far wall again: the controller holds to the stop now, so a step
  // that can only brake brakes.
  map({wall_across(35)});
  d = tick(kOnLeg);
  EXPECT_EQ(d.publish, Publish::kStep) << d.message;
  EXPECT_EQ(d.mode, PlanMode::kBraking);
  EXPECT_NE(d.status, StatsStatus::kDeferred);
}

// A dead end: a wall across the map 7 m ahead of a hovering vehicle (no
// room to move forward with R_s and the margin). Stuck for stuck_time, the
// recovery looks round (a hover, the heading turning right), then takes the
// route it is given (turning the shorter way to the escape leg) or, given
// none, holds the hover with no route.
class RecoveryTest : public AvoidanceSupervisorTest {
 protected:
  static SupervisorSettings dead_end() {
    SupervisorSettings s = settings();
    // Only the route's start is checked for pinches: the wall is the dead
    // end here, not a passage.
    s.passages.look_distance = 1.0;
    return s;
  }
  RecoveryTest() : AvoidanceSupervisorTest(dead_end()) {}

  /// Hovers until the look begins; the heading then turns 0.5 rad a tick
  /// through a full turn. Returns the first hover of the look.
  SupervisorDecision look() {
    start();
    map({wall_across(7)});
    SupervisorDecision d;
    for (int i = 0; i < 80; ++i) {
      d = tick(kOnLeg, Vec3::Zero());
      if (d.publish == Publish::kHover) break;
      EXPECT_EQ(d.publish, Publish::kStep) << i << ": " << d.message;
    }
    EXPECT_EQ(supervisor_.recovery_phase(), RecoveryPhase::kLooking);
    for (int k = 1; k <= 13; ++k) {
      const SupervisorDecision turning = tick(kOnLeg, Vec3::Zero(), 0.5 * k);
      EXPECT_EQ(turning.mode, PlanMode::kLookAround);
    }
    yaw_ = 6.5;
    return d;
  }
  double yaw_ = 0;
};

TEST_F(RecoveryTest, ALookIsAHoverTurningRightAndNoRouteAHoverHeld) {
  const SupervisorDecision d = look();
  ASSERT_EQ(d.publish, Publish::kHover);
  EXPECT_EQ(d.mode, PlanMode::kLookAround);
  EXPECT_EQ(d.status, StatsStatus::kLookingAround);
  EXPECT_EQ(d.message, "recovery: looking around");
  EXPECT_TRUE(logged(d, "recovery: looking around: no way forward"));
  EXPECT_FALSE(d.trajectory.empty());
  // No newer route within route_timeout (10 s) of the look's end.
  SupervisorDecision held;
  for (int i = 0; i < 120 && supervisor_.recovery_phase() != RecoveryPhase::kNoRoute; ++i)
    held = tick(kOnLeg, Vec3::Zero(), yaw_);
  ASSERT_EQ(supervisor_.recovery_phase(), RecoveryPhase::kNoRoute);
  EXPECT_EQ(held.publish, Publish::kHover);
  EXPECT_EQ(held.mode, PlanMode::kBraking);  // a hover, the heading left alone
  EXPECT_EQ(held.status, StatsStatus::kNoRoute);
}

TEST_F(RecoveryTest, AnEscapeToTheLeftTurnsLeftAndIsFramedFromWhereItBegan) {
  look();
  // The route goes west along the wall first, then north past it.
  const std::vector<Vec3> west = {kOnLeg, Vec3(0, -40, -kLegAltitude),
                                  Vec3(100, -40, -kLegAltitude), Vec3(150, 0, -kLegAltitude)};
  for (int i = 0; i < 40; ++i) tick(kOnLeg, Vec3::Zero(), yaw_);  // past route_wait
  route(RouteKind::kForward, west);
  SupervisorDecision d = tick(kOnLeg, Vec3::Zero(), yaw_);
  ASSERT_EQ(supervisor_.recovery_phase(), RecoveryPhase::kTurning) << d.message;
  EXPECT_EQ(d.publish, Publish::kHover);
  EXPECT_EQ(d.mode, PlanMode::kLookAroundLeft);  // west of north is the shorter way left
  EXPECT_EQ(d.status, StatsStatus::kLookingAround);
  // Facing west for face_hold (1 s): the escape leg is flown.
  const double west_yaw = -M_PI / 2;
  for (int i = 0; i < 20 && supervisor_.recovery_phase() != RecoveryPhase::kEscaping; ++i)
    d = tick(kOnLeg, Vec3::Zero(), west_yaw);
  ASSERT_EQ(supervisor_.recovery_phase(), RecoveryPhase::kEscaping);
  ASSERT_EQ(d.publish, Publish::kStep) << d.message;
  EXPECT_EQ(d.message.rfind("escaping: ", 0), 0u) << d.message;
  // 10 m on along it, the step is still framed from where the escape
  // began, towards its end.
  d = tick(Vec3(0, -10, -kLegAltitude), Vec3(0, -kSpeed, 0), west_yaw);
  ASSERT_EQ(d.publish, Publish::kStep) << d.message;
  EXPECT_LT((d.frame.origin - kOnLeg).norm(), 1e-9);
  EXPECT_GT(d.frame.world_from_guidance.col(0).dot(Vec3(0, -1, 0)), 0.99);
  EXPECT_EQ(d.message.rfind("escaping: ", 0), 0u) << d.message;
}

TEST_F(RecoveryTest, AnEscapeToTheRightTurnsRight) {
  look();
  const std::vector<Vec3> east = {kOnLeg, Vec3(0, 40, -kLegAltitude), Vec3(100, 40, -kLegAltitude),
                                  Vec3(150, 0, -kLegAltitude)};
  for (int i = 0; i < 40; ++i) tick(kOnLeg, Vec3::Zero(), yaw_);
  route(RouteKind::kForward, east);
  const SupervisorDecision d = tick(kOnLeg, Vec3::Zero(), yaw_);
  ASSERT_EQ(supervisor_.recovery_phase(), RecoveryPhase::kTurning) << d.message;
  EXPECT_EQ(d.publish, Publish::kHover);
  EXPECT_EQ(d.mode, PlanMode::kLookAround);
}

TEST(RouteDifference, IsTheFarthestPointWithinTheHorizon) {
  const std::vector<Vec3> a = {Vec3(0, 0, 0), Vec3(100, 0, 0)};
  const std::vector<Vec3> b = {Vec3(0, 0, 0), Vec3(50, 4, 0), Vec3(90, 30, 0)};
  EXPECT_NEAR(route_difference(a, b, Vec3::Zero(), 60.0), 4.0, 1e-9);
  EXPECT_NEAR(route_difference(a, b, Vec3::Zero(), 200.0), 30.0, 1e-9);
  EXPECT_TRUE(std::isinf(route_difference({}, b, Vec3::Zero(), 60.0)));
}

}  // namespace
}  // namespace ofn::rh
