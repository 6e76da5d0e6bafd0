// The receding-horizon trajectory optimiser (paper 4.1, Eqs. 1-8): analytic
// gradients, feasibility over the benchmark courses and random fields, warm
// starts, and no NaN on impossible problems.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include "ofn/common/scenario.hpp"
#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/rh_nlp.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"
#include "ofn/world/world.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

// Between collocation points the constraints are only approximately held;
// the 10x finer resampling must stay within this normalised violation. The
// loosest is the commanded acceleration (Eq. 4), which carries the jerk:
// 0.1 on its squared ellipse is 5 % over the limit in magnitude.
constexpr double kBetweenPointsTolerance = 0.1;
constexpr double kMapperMargin = 1.5;  // m, horizontal inflation like the mapper's grid

using mapping::DistanceField;
using mapping::Heightfield;
using testing_support::untimed;

// The true obstacles rasterised at 1 m: a cell within the margin of an
// obstacle's footprint gets the obstacle's height.
Heightfield rasterise(const std::vector<ObstacleSpec>& specs, double ground_altitude,
                      double north_lo, double north_hi, double east_lo, double east_hi) {
  Heightfield field;
  field.resolution = 1.0;
  field.origin_north = north_lo;
  field.origin_east = east_lo;
  field.rows = static_cast<int>(std::ceil(north_hi - north_lo));
  field.cols = static_cast<int>(std::ceil(east_hi - east_lo));
  field.top.assign(static_cast<size_t>(field.rows) * field.cols, 0.0f);
  for (const ObstacleSpec& spec : specs) {
    const world::Obstacle obstacle(spec, ground_altitude);
    const Vec3 lo = obstacle.bounds_min(), hi = obstacle.bounds_max();
    for (int r = field.row_of(lo.x() - kMapperMargin); r <= field.row_of(hi.x() + kMapperMargin);
         ++r)
      for (int c = field.col_of(lo.y() - kMapperMargin); c <= field.col_of(hi.y() + kMapperMargin);
           ++c) {
        if (!field.inside(r, c)) continue;
        const double north = field.cell_centre_north(r), east = field.cell_centre_east(c);
        // The horizontal distance to the footprint: the least over the
        // obstacle's height (trees are not prisms).
        double nearest = 1e9;
        for (double altitude = 0.5; altitude < spec.height; altitude += 1.0)
          nearest = std::min(nearest,
                             obstacle.distance(Vec3(north, east, -(ground_altitude + altitude))));
        if (nearest <= kMapperMargin)
          field.at(r, c) = std::max(field.at(r, c), static_cast<float>(spec.height));
      }
  }
  return field;
}

std::shared_ptr<DistanceField> build_field(const Heightfield& heightfield) {
  auto field = std::make_shared<DistanceField>();
  field->build(heightfield, 0.0, 80.0);
  return field;
}

ClearanceQuery query_of(std::shared_ptr<DistanceField> field) {
  return [field](const Vec3& ned) { return field->query(ned); };
}

Vec3 feet(double x, double y, double h) {
  return course_to_ned(Vec3(x, y, h) * kMetresPerFoot);
}

struct Course {
  Scenario scenario;
  std::shared_ptr<DistanceField> field;
  std::vector<Vec3> route;  // world NED, the hand-made way through
  double obstacles_far_north = 0;
};

Course load_course(const std::string& name, const std::vector<Vec3>& route_feet) {
  Course course;
  course.scenario = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/" + name + ".yaml");
  const Scenario& s = course.scenario;
  course.field = build_field(rasterise(s.obstacles, s.ground_altitude, -45, 140, -85, 85));
  for (const Vec3& p : route_feet) course.route.push_back(feet(p.x(), p.y(), p.z()));
  course.obstacles_far_north = -1e9;
  for (const ObstacleSpec& spec : s.obstacles)
    course.obstacles_far_north =
        std::max(course.obstacles_far_north, world::Obstacle(spec).bounds_max().x());
  return course;
}

// The route's point at north x (linear between its vertices).
Vec3 route_at(const std::vector<Vec3>& route, double north) {
  for (size_t i = 0; i + 1 < route.size(); ++i)
    if (north <= route[i + 1].x()) {
      const double w = (north - route[i].x()) / (route[i + 1].x() - route[i].x());
      return route[i] + std::clamp(w, 0.0, 1.0) * (route[i + 1] - route[i]);
    }
  return route.back();
}

RhProblem course_problem(const Course& course, const Vec3& position) {
  const Scenario& s = course.scenario;
  RhProblem problem;
  problem.frame =
      GuidanceFrame::from_leg(s.waypoints.front().position, s.waypoints.back().position);
  problem.position = position;
  problem.velocity = problem.frame.world_from_guidance.col(0) * s.cruise_speed;
  problem.target = s.waypoints.back().position;
  problem.limits = s.limits;
  const double x0 = problem.frame.to_guidance(position).x();
  const double obstacle_x =
      problem.frame.to_guidance(Vec3(course.obstacles_far_north, 0, 0)).x() + s.limits.clearance;
  problem.terminal_x = std::min(x0 + s.limits.sensor_range, obstacle_x);
  problem.clearance = query_of(course.field);
  return problem;
}

std::string describe(const ConstraintReport& r) {
  std::ostringstream out;
  out << "clearance " << r.clearance << ", forward speed " << r.forward_speed << ", vertical speed "
      << r.vertical_speed << ", total speed " << r.total_speed << ", acceleration "
      << r.acceleration << ", commanded acceleration " << r.commanded_acceleration << ", altitude "
      << r.altitude << ", terminal " << r.terminal;
  return out.str();
}

void expect_meets_constraints(const RhOptimizer& optimizer, const RhProblem& problem,
                              const SolveReport& report, const std::string& label) {
  ASSERT_TRUE(report.feasible) << label << ": " << report.message << " ("
                               << describe(optimizer.check(problem, report.trajectory,
                                                           optimizer.settings().collocation_points))
                               << ", " << report.iterations << " evaluations)";
  EXPECT_LE(report.max_violation, optimizer.settings().feasibility_tolerance) << label;
  const ConstraintReport at_points =
      optimizer.check(problem, report.trajectory, optimizer.settings().collocation_points);
  EXPECT_LE(at_points.worst(), optimizer.settings().feasibility_tolerance + 1e-9)
      << label << ": " << at_points.worst_name();
  const ConstraintReport fine =
      optimizer.check(problem, report.trajectory, 10 * optimizer.settings().collocation_points);
  EXPECT_LE(fine.worst(), kBetweenPointsTolerance) << label << ": " << describe(fine);
  // The start state is met by construction.
  EXPECT_LT((report.trajectory.position(0) - problem.position).norm(), 1e-9) << label;
  EXPECT_LT((report.trajectory.velocity(0) - problem.velocity).norm(), 1e-9) << label;
  EXPECT_LT((report.trajectory.acceleration(0) - problem.acceleration).norm(), 1e-9) << label;
}

// ---------------------------------------------------------------------------

TEST(RhNlp, GradientsMatchCentralDifferences) {
  const Course course = load_course(
      "bench1", {{-100, 0, 120}, {20, 0, 120}, {150, 0, 180}, {260, 0, 180}, {500, 0, 120}});
  // The plain terminal rows, then every optional one (zero a(T) and the
  // stop at the target, whose rows follow the a(T) rows).
  for (const bool optional_rows : {false, true}) {
    for (const bool pitched : {false, true}) {
      RhSettings settings;
      settings.zero_terminal_accel = optional_rows;
      settings.forward_speed_reserve = 0.15;  // its reserve and the reserve's ramp
      RhNlp nlp(settings, BsplineBasis(settings.degree, settings.intervals));
      // Near the wall and a little inside the planned clearance, so that the
      // clearance gradient and its growing requirement are both exercised.
      RhProblem problem = course_problem(course, feet(180, 0, 150));
      // A climbing leg's frame too: the vertical speed rows are the world's.
      if (pitched)
        problem.frame =
            GuidanceFrame::from_leg(problem.position, problem.position + Vec3(8, 3, -6));
      problem.acceleration = Vec3(0.1, -0.05, -0.2);
      problem.stop_at_target = optional_rows;
      nlp.set_problem(problem);
      ASSERT_LT(nlp.start_clearance(), problem.limits.clearance + settings.clearance_margin);
      nlp.set_cost_scale(37.0);

      const InitialGuess guess = RhOptimizer::guess_from_path(course.route, problem, 3.0);
      const Eigen::VectorXd base = nlp.fit(guess);
      std::mt19937 rng(11);
      std::normal_distribution<double> noise(0.0, 0.2);
      const int n = nlp.num_variables();
      const int mi = nlp.num_inequalities(), me = nlp.num_equalities();
      for (int trial = 0; trial < 4; ++trial) {
        Eigen::VectorXd z = base;
        for (int j = 0; j < n; ++j) z(j) += noise(rng);
        z(n - 1) = std::max(z(n - 1), 0.5);
        Eigen::VectorXd gradient(n), ineq(mi), eq(me);
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> ji(mi, n), je(me, n);
        nlp.objective(z.data(), gradient.data());
        nlp.inequalities(z.data(), ineq.data(), ji.data());
        nlp.equalities(z.data(), eq.data(), je.data());
        const double h = 1e-6;
        for (int j = 0; j < n; ++j) {
          Eigen::VectorXd plus = z, minus = z;
          plus(j) += h;
          minus(j) -= h;
          Eigen::VectorXd ip(mi), im(mi), ep(me), em(me);
          const double fp = nlp.objective(plus.data(), nullptr);
          nlp.inequalities(plus.data(), ip.data(), nullptr);
          nlp.equalities(plus.data(), ep.data(), nullptr);
          const double fm = nlp.objective(minus.data(), nullptr);
          nlp.inequalities(minus.data(), im.data(), nullptr);
          nlp.equalities(minus.data(), em.data(), nullptr);
          const double df = (fp - fm) / (2 * h);
          EXPECT_NEAR(gradient(j), df, 1e-4 * std::max(1.0, std::abs(df)))
              << "cost, variable " << j << " trial " << trial;
          for (int r = 0; r < mi; ++r) {
            const double d = (ip(r) - im(r)) / (2 * h);
            EXPECT_NEAR(ji(r, j), d, 1e-4 * std::max(1.0, std::abs(d)))
                << "inequality " << r << " variable " << j << " trial " << trial;
          }
          for (int r = 0; r < me; ++r) {
            const double d = (ep(r) - em(r)) / (2 * h);
            EXPECT_NEAR(je(r, j), d, 1e-4 * std::max(1.0, std::abs(d)))
                << "equality " << r << " variable " << j << " trial " << trial;
          }
        }
      }
    }
  }
}

TEST(RhNlp, FitReproducesASplineGuessAndItsState) {
  RhSettings settings = untimed();
  RhOptimizer optimizer(settings);
  RhProblem problem;
  problem.frame = GuidanceFrame::from_leg(Vec3(0, 0, -30), Vec3(200, 0, -30));
  problem.position = Vec3(0, 0, -30);
  problem.velocity = Vec3(3, 0, 0);
  problem.target = Vec3(200, 0, -30);
  problem.terminal_x = 60;
  problem.limits = Limits{3.048, 0.4877, 1.524, 0, 6.1, 61};
  RhNlp nlp(settings, BsplineBasis(settings.degree, settings.intervals));
  nlp.set_problem(problem);
  const InitialGuess guess = RhOptimizer::guess_straight(problem);
  const BsplineTrajectory fitted = nlp.trajectory(nlp.fit(guess).data());
  EXPECT_NEAR(fitted.duration(), guess.duration, 1e-9);
  for (double t = 0; t <= fitted.duration(); t += 1.0)
    EXPECT_LT((fitted.position(t) - (problem.position + problem.velocity * t)).norm(), 1e-6);
}

// ---------------------------------------------------------------------------

/// The open course's leg and limits, the target its last waypoint; the
/// start state is the caller's.
RhProblem open_course_problem(const Scenario& open) {
  RhProblem problem;
  problem.frame =
      GuidanceFrame::from_leg(open.waypoints.front().position, open.waypoints.back().position);
  problem.limits = open.limits;
  problem.target = open.waypoints.back().position;
  return problem;
}

TEST(RhOptimizer, OpenSpaceFromAStraightGuess) {
  const Scenario open = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  RhOptimizer optimizer(untimed());
  RhProblem problem = open_course_problem(open);
  for (const double along : {0.0, 40.0, 90.0}) {
    problem.position = problem.frame.to_world(Vec3(along, 2.0, 0.0));
    problem.velocity = problem.frame.world_from_guidance.col(0) * open.cruise_speed;
    problem.terminal_x = along + open.limits.sensor_range;
    const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
    expect_meets_constraints(optimizer, problem, report, "open at " + std::to_string(along));
    // Nothing in the way: the optimum flies at full speed.
    EXPECT_GT(report.trajectory.velocity(report.trajectory.duration()).norm(),
              0.9 * open.limits.max_speed);
  }
}

TEST(RhOptimizer, AStartAboveTheAccelerationReserveIsBroughtInsideIt) {
  // The start acceleration comes from the last plan, which is bounded only
  // from its first collocation point on. Taken as it is, a start above the
  // reserve let each plan climb a little higher than the one before.
  const Scenario open = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  RhSettings settings = untimed();
  settings.accel_margin = 0.06;
  RhOptimizer optimizer(settings);
  RhProblem problem = open_course_problem(open);
  problem.position = problem.frame.to_world(Vec3(40.0, 2.0, 0.0));
  problem.velocity = problem.frame.world_from_guidance.col(0) * open.cruise_speed;
  problem.acceleration = problem.frame.world_from_guidance.col(1) * open.limits.max_accel;
  problem.terminal_x = 40.0 + open.limits.sensor_range;
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  ASSERT_TRUE(report.feasible) << report.message;
  const double reserve = (1.0 - settings.accel_margin) * open.limits.max_accel;
  const Vec3 start = report.trajectory.acceleration(0.0);
  EXPECT_NEAR(start.norm(), reserve, 1e-9);
  EXPECT_NEAR(start.normalized().dot(problem.acceleration.normalized()), 1.0, 1e-9);
  // Up to the first collocation point too, where nothing else holds it.
  const double first_point = report.trajectory.duration() / settings.collocation_points;
  for (int i = 0; i <= 20; ++i)
    EXPECT_LE(report.trajectory.acceleration(first_point * i / 20).norm(), 1.005 * reserve);
}

TEST(RhOptimizer, AClimbingLegKeepsTheWorldsVerticalSpeedLimit) {
  // An escape over a wall: a leg that climbs 20 m over 5 m, flown from a
  // hover to a stop at its end. Its guidance frame is pitched, so its z is
  // not the vertical; the vertical speed limit is the world's.
  const Scenario open = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  RhOptimizer optimizer(untimed());
  RhProblem problem;
  problem.position = Vec3(0.0, 0.0, -30.0);
  problem.target = Vec3(5.0, 0.0, -50.0);
  problem.frame = GuidanceFrame::from_leg(problem.position, problem.target);
  problem.limits = open.limits;
  problem.terminal_x = problem.frame.to_guidance(problem.target).x();
  problem.stop_at_target = true;
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  expect_meets_constraints(optimizer, problem, report, "climbing leg");
  const double T = report.trajectory.duration();
  EXPECT_LT((report.trajectory.position(T) - problem.target).norm(), 0.05);
  double fastest_climb = 0;
  for (int i = 0; i <= 400; ++i)
    fastest_climb = std::max(fastest_climb, -report.trajectory.velocity(T * i / 400).z());
  // It climbs at the limit (the speed along the leg alone would allow
  // twice that), and not above it beyond the resampling tolerance.
  EXPECT_LE(fastest_climb, 1.01 * open.limits.max_vertical_speed);
  EXPECT_GT(fastest_climb, 0.9 * open.limits.max_vertical_speed);
}

TEST(RhOptimizer, ASidewaysPlanKeepsItsForwardSpeedReserve) {
  // Target 60 m beside the leg and 5 m along it, from a hover: the plan flies
  // almost sideways. Under the forward speed rule it keeps u >= r |v|^2 /
  // (|v|^2 + 1 m^2/s^2) once the reserve has built up (1 s), room for the
  // controller's tracking error; a dead-end escape (rule relaxed) does not.
  const Scenario open = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  RhSettings settings = untimed();
  settings.speed_margin = 0.005;  // the service's reserves
  settings.accel_margin = 0.06;
  settings.forward_speed_reserve = 0.15;
  RhOptimizer optimizer(settings);
  RhProblem problem;
  problem.position = Vec3(0.0, 0.0, -30.0);
  problem.target = Vec3(5.0, 60.0, -30.0);
  problem.frame = GuidanceFrame::from_leg(problem.position, Vec3(100.0, 0.0, -30.0));
  problem.limits = open.limits;
  problem.terminal_x = 5.0;
  problem.stop_at_target = true;
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  expect_meets_constraints(optimizer, problem, report, "sideways");
  const double T = report.trajectory.duration();
  const double max_speed = (1.0 - settings.speed_margin) * open.limits.max_speed;
  double fastest = 0, least_reserve_kept = 1e9;
  for (int i = 0; i <= 400; ++i) {
    const double t = T * i / 400;
    const Vec3 v = report.trajectory.velocity(t);
    fastest = std::max(fastest, v.norm());
    if (t < 1.0) continue;
    const double reserve =
        settings.forward_speed_reserve * v.squaredNorm() / (v.squaredNorm() + 1.0);
    least_reserve_kept = std::min(least_reserve_kept, v.x() - reserve);
  }
  EXPECT_GT(fastest, 0.5 * max_speed);  // it did fly sideways, and fast
  EXPECT_GT(least_reserve_kept, -0.01 * max_speed);

  // A climb in place keeps no reserve (the heading holds there): from a
  // hover to 20 m up and 0.5 m on, at rest.
  RhProblem climb = problem;
  climb.target = Vec3(0.5, 0.0, -50.0);
  climb.terminal_x = 0.5;
  const SolveReport up = optimizer.solve(climb, RhOptimizer::guess_straight(climb));
  expect_meets_constraints(optimizer, climb, up, "climb in place");
  EXPECT_LT((up.trajectory.position(up.trajectory.duration()) - climb.target).norm(), 0.05);

  problem.limits.min_forward_speed = -open.limits.max_speed;  // an escape
  problem.target = Vec3(-5.0, 60.0, -30.0);
  problem.terminal_x = -5.0;
  const SolveReport escape = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  expect_meets_constraints(optimizer, problem, escape, "escape sideways and back");
}

TEST(RhOptimizer, StopsAtRestOnTheLastWaypoint) {
  // The last waypoint 40 m ahead, the vehicle 3 m beside the leg at cruise
  // speed: the trajectory ends on the waypoint at rest, within the limits.
  const Scenario open = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  RhOptimizer optimizer(untimed());
  RhProblem problem = open_course_problem(open);
  problem.terminal_x = problem.frame.to_guidance(problem.target).x();
  problem.position = problem.frame.to_world(Vec3(problem.terminal_x - 40.0, 3.0, 0.0));
  problem.velocity = problem.frame.world_from_guidance.col(0) * open.cruise_speed;
  problem.stop_at_target = true;
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  expect_meets_constraints(optimizer, problem, report, "stop at the last waypoint");
  const double T = report.trajectory.duration();
  EXPECT_LT((report.trajectory.position(T) - problem.target).norm(), 0.05);
  EXPECT_LT(report.trajectory.velocity(T).norm(), 0.02);

  // Without the stop, the same problem only reaches the waypoint's x.
  problem.stop_at_target = false;
  const SolveReport passing = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  ASSERT_TRUE(passing.feasible) << passing.message;
  EXPECT_GT(passing.trajectory.velocity(passing.trajectory.duration()).norm(), 1.0);
}

struct CourseCase {
  std::string name;
  std::vector<Vec3> route_feet;     // course frame, ft
  std::vector<double> starts_feet;  // course x of the start positions on the route
  // Test logs name the course, not the object's bytes.
  friend void PrintTo(const CourseCase& c, std::ostream* os) { *os << c.name; }
};

class RhOptimizerCourse : public ::testing::TestWithParam<CourseCase> {};

TEST_P(RhOptimizerCourse, FeasibleAtEveryStartAndBetweenCollocationPoints) {
  const CourseCase& c = GetParam();
  const Course course = load_course(c.name, c.route_feet);
  RhOptimizer optimizer(untimed());
  for (const double start_x : c.starts_feet) {
    const Vec3 position = route_at(course.route, start_x * kMetresPerFoot);
    const RhProblem problem = course_problem(course, position);
    const InitialGuess guess =
        RhOptimizer::guess_from_path(course.route, problem, course.scenario.cruise_speed);
    const SolveReport report = optimizer.solve(problem, guess);
    expect_meets_constraints(optimizer, problem, report,
                             c.name + " from x = " + std::to_string(start_x) + " ft");
  }
}

TEST_P(RhOptimizerCourse, ScreeningKeepsEveryConstraintAndTheCost) {
  // Warm solves (the only ones screened) a step along the full solution,
  // with and without screening.
  const CourseCase& c = GetParam();
  const Course course = load_course(c.name, c.route_feet);
  RhOptimizer full(untimed());
  RhSettings settings = untimed();
  settings.screening_margin = 0.5;
  RhOptimizer screened(settings);
  const int all_rows =
      full.settings().collocation_points * kNumPointConstraints + RhNlp::kNumTerminalInequalities;
  int rounds_above_one = 0;
  for (const double start_x : c.starts_feet) {
    const std::string label = c.name + " from x = " + std::to_string(start_x) + " ft";
    const Vec3 position = route_at(course.route, start_x * kMetresPerFoot);
    const RhProblem problem = course_problem(course, position);
    const InitialGuess guess =
        RhOptimizer::guess_from_path(course.route, problem, course.scenario.cruise_speed);
    const SolveReport cold = full.solve(problem, guess);
    ASSERT_TRUE(cold.feasible) << label;
    EXPECT_EQ(screened.solve(problem, guess).subproblem_rows, all_rows) << label << ", cold";
    for (const double step : {0.1, 1.0, 3.0}) {
      RhProblem next = problem;
      next.position = cold.trajectory.position(step);
      next.velocity = cold.trajectory.velocity(step);
      next.acceleration = cold.trajectory.acceleration(step);
      const InitialGuess warm = RhOptimizer::guess_from_previous(cold.trajectory, step, next);
      const std::string at = label + ", warm " + std::to_string(step) + " s on";
      const SolveReport reference = full.solve(next, warm);
      const SolveReport report = screened.solve(next, warm);
      ASSERT_TRUE(reference.feasible) << at;
      ASSERT_TRUE(report.feasible) << at << ": " << report.message;
      EXPECT_LT(report.subproblem_rows, all_rows) << at;
      EXPECT_LE(report.cost, 1.01 * reference.cost) << at;
      // Every row at the collocation points, left out or not; between them
      // no worse than the full solve (a warm start from an arbitrary state
      // can bulge there either way).
      const int points = screened.settings().collocation_points;
      EXPECT_LE(screened.check(next, report.trajectory, points).worst(),
                screened.settings().feasibility_tolerance + 1e-9)
          << at;
      const double fine = screened.check(next, report.trajectory, 10 * points).worst();
      const double fine_full = full.check(next, reference.trajectory, 10 * points).worst();
      EXPECT_LE(fine, std::max(kBetweenPointsTolerance, fine_full + 0.01)) << at;
      rounds_above_one += report.rounds > 1 ? 1 : 0;
    }
  }
  // Rows left out at the start joined in some solves: that path is flown too.
  EXPECT_GT(rounds_above_one, 0);
}

INSTANTIATE_TEST_SUITE_P(
    Benchmarks, RhOptimizerCourse,
    ::testing::Values(
        CourseCase{"bench1",
                   {{-100, 0, 120}, {20, 0, 120}, {150, 0, 180}, {260, 0, 180}, {500, 0, 120}},
                   {-100, 0, 60, 120, 170}},
        CourseCase{"bench2",
                   {{-100, 0, 120},
                    {60, 0, 120},
                    {160, 55, 120},
                    {240, 55, 120},
                    {340, 0, 120},
                    {500, 0, 120}},
                   {-100, 40, 100, 150}},
        CourseCase{"bench3",
                   {{-100, 0, 120}, {20, 0, 120}, {150, 0, 180}, {260, 0, 180}, {500, 0, 120}},
                   {-100, 0, 60, 120, 170}},
        CourseCase{"bench4",
                   {{-100, 0, 120},
                    {40, 0, 120},
                    {150, 75, 120},
                    {250, 75, 120},
                    {360, 0, 120},
                    {500, 0, 120}},
                   {-100, 40, 100, 150}},
        CourseCase{"bench5",
                   {{-100, 0, 120},
                    {20, 0, 120},
                    {90, 50, 120},
                    {150, 50, 120},
                    {290, -50, 120},
                    {350, -50, 120},
                    {450, 0, 120},
                    {500, 0, 120}},
                   {-100, 0, 60, 120, 200}},
        CourseCase{"bench6",
                   {{-100, 0, 120}, {100, 0, 120}, {175, 0, 120}, {255, 40, 120}, {500, 40, 120}},
                   {-100, 0, 60, 120, 150}},
        CourseCase{"tree",
                   {{-100, 0, 60}, {60, 0, 60}, {200, 0, 125}, {380, 0, 125}, {500, 0, 60}},
                   {-100, 60, 150, 220}}),
    [](const ::testing::TestParamInfo<CourseCase>& info) { return info.param.name; });

// ---------------------------------------------------------------------------

TEST(RhOptimizer, SeededRandomFieldsWithAFreeCorridor) {
  const Limits limits{3.048, 0.4877, 1.524, 0.0, 6.096, 60.96};
  const double altitude = 30.0;
  RhOptimizer optimizer(untimed());
  const double keep_out =
      limits.clearance + optimizer.settings().clearance_margin + kMapperMargin + 4.0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // A gently weaving corridor, and obstacles placed clear of it.
    std::vector<Vec3> corridor;
    for (int k = 0; k <= 5; ++k)
      corridor.emplace_back(40.0 * k, k == 0 ? 0.0 : -12.0 + 24.0 * unit(rng), -altitude);
    auto corridor_distance = [&](double north, double east) {
      double best = 1e9;
      for (size_t i = 0; i + 1 < corridor.size(); ++i) {
        const Eigen::Vector2d a = corridor[i].head<2>(), b = corridor[i + 1].head<2>();
        const Eigen::Vector2d p(north, east);
        const double u = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (p - a - u * (b - a)).norm());
      }
      return best;
    };
    std::vector<ObstacleSpec> specs;
    for (int attempt = 0; attempt < 200 && specs.size() < 8; ++attempt) {
      ObstacleSpec spec;
      spec.kind = unit(rng) < 0.5 ? ObstacleSpec::Kind::kBox : ObstacleSpec::Kind::kCylinder;
      spec.id = static_cast<int>(specs.size()) + 1;
      spec.north = 30.0 + 150.0 * unit(rng);
      spec.east = -50.0 + 100.0 * unit(rng);
      spec.length = 4.0 + 12.0 * unit(rng);
      spec.width = spec.kind == ObstacleSpec::Kind::kBox ? 4.0 + 12.0 * unit(rng) : spec.length;
      spec.height = 10.0 + 50.0 * unit(rng);
      const double half = 0.5 * std::hypot(spec.length, spec.width);
      const bool low = spec.height + keep_out < altitude;
      if (!low && corridor_distance(spec.north, spec.east) < half + keep_out) continue;
      specs.push_back(spec);
    }
    Course course;
    course.field = build_field(rasterise(specs, 0.0, -20, 220, -80, 80));
    course.route = corridor;
    course.scenario.waypoints = {Waypoint{Vec3(0, 0, -altitude), 5},
                                 Waypoint{Vec3(250, 0, -altitude), 5}};
    course.scenario.cruise_speed = limits.max_speed;
    course.scenario.limits = limits;
    course.obstacles_far_north = -1e9;
    for (const ObstacleSpec& spec : specs)
      course.obstacles_far_north =
          std::max(course.obstacles_far_north, world::Obstacle(spec).bounds_max().x());
    for (const double start : {0.0, 70.0}) {
      const RhProblem problem = course_problem(course, route_at(corridor, start));
      const SolveReport report =
          optimizer.solve(problem, RhOptimizer::guess_from_path(corridor, problem, 3.0));
      expect_meets_constraints(optimizer, problem, report,
                               "seed " + std::to_string(seed) + " from " + std::to_string(start));
    }
  }
}

// ---------------------------------------------------------------------------

TEST(RhOptimizer, WarmStartsTakeFewerIterationsThanColdStarts) {
  const Course course = load_course(
      "bench4",
      {{-100, 0, 120}, {40, 0, 120}, {150, 75, 120}, {250, 75, 120}, {360, 0, 120}, {500, 0, 120}});
  RhOptimizer optimizer(untimed());
  RhProblem problem = course_problem(course, route_at(course.route, 20 * kMetresPerFoot));
  SolveReport previous =
      optimizer.solve(problem, RhOptimizer::guess_from_path(course.route, problem, 3.048));
  ASSERT_TRUE(previous.feasible) << previous.message;
  int warm_iterations = 0, cold_iterations = 0, steps = 0;
  for (int step = 0; step < 20; ++step) {
    const BsplineTrajectory& flown = previous.trajectory;
    RhProblem next = course_problem(course, flown.position(0.1));
    next.velocity = flown.velocity(0.1);
    next.acceleration = flown.acceleration(0.1);
    const SolveReport cold =
        optimizer.solve(next, RhOptimizer::guess_from_path(course.route, next, 3.048));
    const SolveReport warm =
        optimizer.solve(next, RhOptimizer::guess_from_previous(flown, 0.1, next));
    EXPECT_TRUE(warm.warm_started);
    ASSERT_TRUE(warm.feasible) << "step " << step << ": " << warm.message;
    warm_iterations += warm.iterations;
    cold_iterations += cold.iterations;
    ++steps;
    previous = warm;
  }
  EXPECT_LT(warm_iterations, cold_iterations) << "mean warm " << double(warm_iterations) / steps
                                              << " cold " << double(cold_iterations) / steps;
}

// ---------------------------------------------------------------------------

bool all_finite(const SolveReport& report) {
  for (const Vec3& c : report.trajectory.control_points())
    if (!c.allFinite()) return false;
  return std::isfinite(report.cost) && std::isfinite(report.max_violation) &&
         (report.trajectory.empty() || std::isfinite(report.trajectory.duration()));
}

TEST(RhOptimizer, StartInsideAnObstacleNeverGivesNaN) {
  const Course course = load_course("bench4", {{-100, 0, 120}, {500, 0, 120}});
  RhOptimizer optimizer(untimed());
  const RhProblem problem = course_problem(course, feet(200, 0, 120));  // inside the cube
  ASSERT_LT(problem.clearance(problem.position).distance, 0.0);
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  EXPECT_TRUE(all_finite(report)) << report.message;
  if (report.feasible) {
    EXPECT_LE(optimizer.check(problem, report.trajectory, 24).worst(),
              optimizer.settings().feasibility_tolerance + 1e-9);
  }
}

TEST(RhOptimizer, TargetBehindAWallNeverGivesNaN) {
  // A wall across the whole map, taller than the field: nothing gets past.
  Heightfield heightfield;
  heightfield.origin_north = -20;
  heightfield.origin_east = -60;
  heightfield.rows = 140;
  heightfield.cols = 120;
  heightfield.top.assign(static_cast<size_t>(heightfield.rows) * heightfield.cols, 0.0f);
  for (int r = 60; r < 64; ++r)
    for (int c = 0; c < heightfield.cols; ++c) heightfield.at(r, c) = 200.0f;
  RhProblem problem;
  problem.frame = GuidanceFrame::from_leg(Vec3(0, 0, -30), Vec3(200, 0, -30));
  problem.position = Vec3(0, 0, -30);
  problem.velocity = Vec3(3.048, 0, 0);
  problem.target = Vec3(200, 0, -30);
  problem.terminal_x = 60.0;
  problem.limits = Limits{3.048, 0.4877, 1.524, 0.0, 6.096, 60.96};
  problem.clearance = query_of(build_field(heightfield));
  RhOptimizer optimizer(untimed());
  const SolveReport report = optimizer.solve(problem, RhOptimizer::guess_straight(problem));
  EXPECT_FALSE(report.feasible);
  EXPECT_TRUE(all_finite(report)) << report.message;
}

TEST(RhOptimizer, BadProblemsAreReportedNotThrown) {
  RhOptimizer optimizer(untimed());
  RhProblem problem;
  problem.frame = GuidanceFrame::from_leg(Vec3(0, 0, -30), Vec3(200, 0, -30));
  problem.position = Vec3(0, 0, -30);
  problem.velocity = Vec3(3, 0, 0);
  problem.target = Vec3(200, 0, -30);
  problem.terminal_x = 60;
  problem.limits = Limits{3.048, 0.4877, 1.524, 0.0, 6.096, 60.96};

  const SolveReport empty = optimizer.solve(problem, InitialGuess{});
  EXPECT_FALSE(empty.feasible);
  EXPECT_NE(empty.message.find("empty"), std::string::npos) << empty.message;
  EXPECT_TRUE(empty.trajectory.empty());

  RhProblem nan_state = problem;
  nan_state.velocity.x() = std::nan("");
  const SolveReport bad = optimizer.solve(nan_state, RhOptimizer::guess_straight(problem));
  EXPECT_FALSE(bad.feasible);
  EXPECT_FALSE(bad.message.empty());
  EXPECT_TRUE(bad.trajectory.empty());

  RhProblem nan_field = problem;
  nan_field.clearance = [](const Vec3&) {
    return mapping::DistanceSample{std::nan(""), Vec3::Zero()};
  };
  const SolveReport nan_clearance =
      optimizer.solve(nan_field, RhOptimizer::guess_straight(problem));
  EXPECT_FALSE(nan_clearance.feasible);
  EXPECT_TRUE(all_finite(nan_clearance));

  RhSettings bad_settings;
  bad_settings.degree = 2;
  EXPECT_THROW(RhOptimizer{bad_settings}, std::invalid_argument);
}

TEST(RhOptimizer, RequiredClearanceLetsAStartInsideClimbOut) {
  RhOptimizer optimizer(untimed());
  RhProblem problem;
  problem.limits = Limits{3.0, 0.5, 1.5, 0.0, 6.0, 60.0};
  const double planned = 6.0 + optimizer.settings().clearance_margin;
  EXPECT_DOUBLE_EQ(optimizer.required_clearance(problem, 20.0, 0.0), planned);
  // From a hover, the start clearance up as far as the vehicle could get
  // from rest: after the largest time constant, at half the acceleration
  // limit, then at the speed limit (each less its margin).
  const double delay = optimizer.settings().time_constants.maxCoeff();
  const double accel = 0.5 * (1.0 - optimizer.settings().accel_margin) * 0.5;
  const double speed = (1.0 - optimizer.settings().speed_margin) * 3.0;
  EXPECT_DOUBLE_EQ(optimizer.required_clearance(problem, 4.0, 0.0), 4.0);
  EXPECT_DOUBLE_EQ(optimizer.required_clearance(problem, 4.0, delay), 4.0);
  EXPECT_NEAR(optimizer.required_clearance(problem, 4.0, delay + 2.0), 4.0 + 0.5 * accel * 4.0,
              1e-12);
  EXPECT_DOUBLE_EQ(optimizer.required_clearance(problem, 4.0, 30.0), planned);
  EXPECT_NEAR(optimizer.required_clearance(problem, -2.0, delay + 1.0), 0.5 * accel, 1e-12);
  // A moving start: the ramp at the speed limit from t = 0.
  RhProblem moving = problem;
  moving.velocity = Vec3(1.0, 0, 0);
  EXPECT_NEAR(optimizer.required_clearance(moving, 4.0, 0.5), 4.0 + speed * 0.5, 1e-12);
  const double t_full = delay + speed / accel;  // at the speed limit from then on
  problem.limits.clearance = 100.0;             // not reached by then
  EXPECT_NEAR(optimizer.required_clearance(problem, 0.0, t_full + 0.1) -
                  optimizer.required_clearance(problem, 0.0, t_full),
              speed * 0.1, 1e-9);
}

TEST(RhOptimizer, GuessesReachTheTerminalX) {
  RhProblem problem;
  problem.frame = GuidanceFrame::from_leg(Vec3(0, 0, -30), Vec3(200, 0, -30));
  problem.position = Vec3(10, 1, -30);
  problem.velocity = Vec3(3, 0, 0);
  problem.terminal_x = 70;
  problem.limits = Limits{3.0, 0.5, 1.5, 0.0, 6.0, 60.0};
  const InitialGuess straight = RhOptimizer::guess_straight(problem);
  EXPECT_NEAR(straight.positions.back().x(), 70.0, 1e-9);
  EXPECT_NEAR(straight.duration, 20.0, 1e-9);

  // A path that ends early is extended along the leg.
  const std::vector<Vec3> path{Vec3(0, 0, -30), Vec3(30, 10, -30), Vec3(50, 10, -30)};
  const InitialGuess along = RhOptimizer::guess_from_path(path, problem, 2.0);
  EXPECT_NEAR(along.positions.back().x(), 70.0, 1e-9);
  EXPECT_NEAR(along.positions.back().y(), 10.0, 1e-9);
  EXPECT_LT((along.positions.front() - problem.position).norm(), 1e-9);

  // A previous solution that ends early is extended at its end velocity.
  const BsplineBasis basis(5, 6);
  std::vector<Vec3> points;
  for (int j = 0; j < basis.num_control_points(); ++j) points.emplace_back(4.0 * j, 1, -30);
  const BsplineTrajectory previous(5, basis.knots(), points, 13.0);
  const InitialGuess warm = RhOptimizer::guess_from_previous(previous, 1.0, problem);
  EXPECT_TRUE(warm.warm);
  EXPECT_LT((warm.positions.front() - previous.position(1.0)).norm(), 1e-9);
  EXPECT_NEAR(warm.positions.back().x(), 70.0, 1e-6);
}

}  // namespace
}  // namespace ofn::rh
