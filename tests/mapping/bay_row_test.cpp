// A row of bays on synthetic ground: asphalt with a painted front line and separators of known
// positions and grey values, seeded noise, seen from a viewer at the cloud's origin.
#include "romo/mapping/bay_row.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

// The row in its own frame: the front line at u = line_u across the viewer's sight, the
// separators from it to u = line_u + separator_length (negative: towards the viewer) at v = each
// of separators_v; 0.12 m wide paint, as a car park's.
struct Row {
  double line_u = 6.0;
  double separator_length = 5.0;
  std::vector<double> separators_v = {-7.5, -4.9, -2.3, 1.2, 3.8, 6.4};  // a free bay 3.5 m wide
  double paint_width = 0.12;
  float asphalt = 80.f, paint = 180.f;
  float noise = 12.f;           // uniform +-, of the grey values
  double density_per_m2 = 150;  // what stereo leaves of the ground 6-12 m away
};

bool OnPaint(const Row& row, double u, double v) {
  const double half = row.paint_width / 2;
  if (std::abs(u - row.line_u) <= half && std::abs(v) <= 10.0) return true;
  const double u0 = std::min(row.line_u, row.line_u + row.separator_length);
  const double u1 = std::max(row.line_u, row.line_u + row.separator_length);
  if (u < u0 || u > u1) return false;
  for (double s : row.separators_v) {
    if (std::abs(v - s) <= half) return true;
  }
  return false;
}

// Ground points over u in [0, 13], v in [-10, 10] of the row's frame, turned by @p yaw about the
// viewer; every point is ground.
PointCloud MakeGround(const Row& row, double yaw, std::vector<int>* ground, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u_of(0.0, 13.0), v_of(-10.0, 10.0);
  std::uniform_real_distribution<float> grey_noise(-row.noise, row.noise);
  const auto n = static_cast<int>(row.density_per_m2 * 13.0 * 20.0);
  const double c = std::cos(yaw), s = std::sin(yaw);
  PointCloud cloud;  // filled in place: PushBack per point is quadratic under ASan
  cloud.Resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double u = u_of(rng), v = v_of(rng);
    cloud.xyz.col(i) = Eigen::Vector3f(static_cast<float>(c * u - s * v), static_cast<float>(s * u + c * v), 0.f);
    cloud.sigma_z_m[static_cast<std::size_t>(i)] = 0.02f;
    cloud.intensity[static_cast<std::size_t>(i)] = (OnPaint(row, u, v) ? row.paint : row.asphalt) + grey_noise(rng);
    ground->push_back(i);
  }
  return cloud;
}

// The row frame's (u, v) point in the cloud frame.
Eigen::Vector2d InCloud(double u, double v, double yaw) {
  return {std::cos(yaw) * u - std::sin(yaw) * v, std::sin(yaw) * u + std::cos(yaw) * v};
}

TEST(BayRowTest, FindsTheFrontLineAndTheSeparatorsBehindIt) {
  const Row row;
  const double yaw = 0.3;
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(row, yaw, &ground);
  const std::optional<BayRow> found = FindBayRow(cloud, ground, BayRowParams{});
  ASSERT_TRUE(found.has_value());
  // Heading from ~20 m of line: well within 1 deg; the line's paint is 0.12 m wide, so a point of
  // it is within 0.06 m of its centre line, which the mean of many points nears further.
  const Eigen::Vector2d into_true = InCloud(1.0, 0.0, yaw) - InCloud(0.0, 0.0, yaw);
  EXPECT_GT(found->into_bays.dot(into_true), std::cos(1.0 * 3.14159265 / 180.0)) << "into the bays, away from the viewer";
  EXPECT_NEAR(found->Depth(InCloud(row.line_u, -3.0, yaw)), 0.0, 0.05);
  EXPECT_NEAR(found->Depth(InCloud(row.line_u, 5.0, yaw)), 0.0, 0.05);
  EXPECT_GE(found->covered_m, 15.0);
  // Each separator within a 0.1 m bin of its centre line.
  ASSERT_EQ(found->separators_m.size(), row.separators_v.size());
  std::vector<double> expected;
  for (double v : row.separators_v) expected.push_back(found->Along(InCloud(row.line_u, v, yaw)));
  std::sort(expected.begin(), expected.end());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_NEAR(found->separators_m[k], expected[k], 0.1) << "separator " << k;
  }
}

TEST(BayRowTest, ALineWithItsSeparatorsOnTheViewersSideIsTheBaysFarEndNotARow) {
  Row kerb;
  kerb.line_u = 9.0;
  kerb.separator_length = -5.0;  // the bays between the viewer and the line
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(kerb, 0.0, &ground);
  EXPECT_FALSE(FindBayRow(cloud, ground, BayRowParams{}).has_value());
  // The line itself is found: a viewer taken to stand on it would see the bays on its side.
  BayRowParams anywhere;
  anywhere.viewer_on_line_m = 20.0;
  const std::optional<BayRow> found = FindBayRow(cloud, ground, anywhere);
  ASSERT_TRUE(found.has_value());
  EXPECT_LT(found->into_bays.x(), -0.99);
}

TEST(BayRowTest, AViewerOnTheLineFindsTheBaysOnTheSideShowingTheSeparators) {
  // Entering a bay: the viewer 1 m from the line (within viewer_on_line_m), the separators
  // beyond it or around the viewer.
  for (const double length : {5.0, -5.0}) {
    Row row;
    row.line_u = 7.5;  // x = 1 once shifted
    row.separator_length = length;
    std::vector<int> ground;
    PointCloud cloud = MakeGround(row, 0.0, &ground);
    for (std::size_t i = 0; i < cloud.size(); ++i) cloud.xyz(0, static_cast<Eigen::Index>(i)) -= 6.5f;  // u in [-6.5, 6.5]
    const std::optional<BayRow> found = FindBayRow(cloud, ground, BayRowParams{});
    ASSERT_TRUE(found.has_value()) << "separators towards " << length;
    EXPECT_GT(found->into_bays.x() * length, 0.99 * std::abs(length)) << "separators towards " << length;
    EXPECT_EQ(found->separators_m.size(), row.separators_v.size());
  }
}

TEST(BayRowTest, GroundWithoutPaintHasNoRow) {
  Row none;
  none.paint = none.asphalt;
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(none, 0.0, &ground);
  EXPECT_FALSE(FindBayRow(cloud, ground, BayRowParams{}).has_value());
}

TEST(BayRowTest, BadParamsAndIndicesAreClearErrors) {
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(Row{}, 0.0, &ground);
  BayRowParams flat;
  flat.contrast = 1.0;
  try {
    FindBayRow(cloud, ground, flat);
    FAIL() << "a contrast of 1 must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("contrast"), std::string::npos) << e.what();
  }
  BayRowParams band;
  band.separator_to_m = band.separator_from_m;
  EXPECT_THROW(FindBayRow(cloud, ground, band), Error);
  std::vector<int> outside = ground;
  outside.push_back(static_cast<int>(cloud.size()));
  try {
    FindBayRow(cloud, outside, BayRowParams{});
    FAIL() << "an index outside the cloud must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(cloud.size())), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace romo::mapping
