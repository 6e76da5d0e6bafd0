// The baseline's programme alone: its analytic gradient and Jacobian agree
// with central differences of its own cost and constraints on a real
// course, its variables map onto the control points as documented, and a
// fitted straight path gives a curve along that path.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <utility>
#include <vector>

#include "ofn/common/scenario.hpp"
#include "ofn/sim/time_optimal_programme.hpp"
#include "ofn/world/world.hpp"

namespace ofn::baseline {
namespace {

Scenario course_scenario(const std::string& name) {
  const auto path = std::filesystem::path(OFN_SOURCE_DIR) / "sim" / "scenarios" / (name + ".yaml");
  return load_scenario(path.string());
}

struct ProgrammeOnACourse {
  explicit ProgrammeOnACourse(const std::string& name)
      : scenario(course_scenario(name)),
        world(scenario.obstacles, scenario.ground_altitude),
        course(make_course(scenario, world, BaselineSettings{})),
        programme(course, 5, 12, duration(), 0.5, 1.0) {}
  double duration() const {
    return 1.1 * (*scenario.finish_gate - scenario.start_position.x()) / scenario.limits.max_speed;
  }
  /// A path straight along north to the finish plane, off the centreline by
  /// `offset` east and `rise` up in its middle: some rows active, some not.
  std::vector<double> guess(double offset, double rise) const {
    const Vec3 start = course.start;
    const double length = course.finish_x - start.x();
    return programme.fit(
        [&](double f) {
          const double bump = std::sin(M_PI * f);
          return Vec3(start.x() + f * length, start.y() + offset * bump, start.z() - rise * bump);
        },
        duration());
  }
  Scenario scenario;
  world::World world;
  Course course;
  Programme programme;
};

TEST(TimeOptimalProgramme, VariablesMapOntoTheFreeControlPoints) {
  const ProgrammeOnACourse p("bench3");
  const int n = p.programme.num_control_points();
  ASSERT_EQ(n, 12 + 5);
  EXPECT_EQ(p.programme.num_variables(), 3 * n - 9);
  // Points 0..2 follow from the start state and T; the last one's x is the
  // finish plane; every other coordinate is one variable after T.
  std::vector<int> seen(static_cast<size_t>(p.programme.num_variables()), 0);
  seen[0] = 1;  // T
  for (int i = 0; i < n; ++i)
    for (int axis = 0; axis < 3; ++axis) {
      const int j = p.programme.var_index(i, axis);
      if (i < 3 || (i == n - 1 && axis == 0)) {
        EXPECT_EQ(j, -1) << i << " " << axis;
        continue;
      }
      ASSERT_GE(j, 1);
      ASSERT_LT(j, p.programme.num_variables());
      ++seen[static_cast<size_t>(j)];
    }
  for (int count : seen) EXPECT_EQ(count, 1);
}

TEST(TimeOptimalProgramme, AFittedPathStartsOnTheStateAndEndsOnTheFinishPlane) {
  const ProgrammeOnACourse p("bench3");
  const std::vector<double> z = p.guess(0.0, 0.0);
  EXPECT_NEAR(p.programme.duration(z.data()), p.duration(), 1e-9);
  const BsplineTrajectory curve = p.programme.trajectory(z.data());
  EXPECT_TRUE(curve.position(0.0).isApprox(p.course.start, 1e-9));
  EXPECT_TRUE(curve.velocity(0.0).isApprox(p.course.start_velocity, 1e-9));
  EXPECT_LT(curve.acceleration(0.0).norm(), 1e-9);
  EXPECT_NEAR(curve.position(curve.duration()).x(), p.course.finish_x, 1e-9);
  // Straight along north: no sideways or vertical excursion.
  for (int k = 0; k <= 20; ++k) {
    const Vec3 q = curve.position(curve.duration() * k / 20.0);
    EXPECT_NEAR(q.y(), p.course.start.y(), 1e-6);
    EXPECT_NEAR(q.z(), p.course.start.z(), 1e-6);
  }
}

TEST(TimeOptimalProgramme, GradientAndJacobianAgreeWithCentralDifferences) {
  for (const char* name : {"bench3", "bench4"}) {
    const ProgrammeOnACourse p(name);
    const Programme& programme = p.programme;
    const int nv = programme.num_variables(), nc = programme.num_constraints();
    for (const auto& [offset, rise] : {std::pair{0.0, 0.0}, std::pair{8.0, -3.0}}) {
      std::vector<double> z = p.guess(offset, rise);
      std::vector<double> grad(static_cast<size_t>(nv));
      programme.objective(z.data(), grad.data());
      std::vector<double> values(static_cast<size_t>(nc)), jac(static_cast<size_t>(nc) * nv);
      programme.constraints(z.data(), values.data(), jac.data());
      std::vector<double> up(static_cast<size_t>(nc)), down(static_cast<size_t>(nc));
      int rows_checked = 0;
      for (int j = 0; j < nv; ++j) {
        const double h = 1e-6;
        const double keep = z[j];
        z[j] = keep + h;
        const double f_up = programme.objective(z.data(), nullptr);
        programme.constraints(z.data(), up.data(), nullptr);
        z[j] = keep - h;
        const double f_down = programme.objective(z.data(), nullptr);
        programme.constraints(z.data(), down.data(), nullptr);
        z[j] = keep;
        SCOPED_TRACE(testing::Message() << name << " offset " << offset << " variable " << j);
        EXPECT_NEAR(grad[j], (f_up - f_down) / (2 * h), 1e-4 * (1 + std::abs(grad[j])));
        for (int r = 0; r < nc; ++r) {
          // The clearance row's own gradient is a central difference of
          // the distance (1e-4 m): compared more loosely, and not across a
          // change of nearest surface.
          const double numeric = (up[r] - down[r]) / (2 * h);
          const double analytic = jac[static_cast<size_t>(r) * nv + j];
          const bool clearance = r % kRows == kClearanceRow;
          if (clearance && std::abs(numeric) > 1e3) continue;
          const double tolerance = clearance ? 2e-2 : 1e-4;
          EXPECT_NEAR(analytic, numeric, tolerance * (1 + std::abs(numeric))) << "row " << r;
          ++rows_checked;
        }
      }
      EXPECT_GT(rows_checked, nv * nc / 2);
    }
  }
}

}  // namespace
}  // namespace ofn::baseline
