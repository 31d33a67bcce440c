#include "romo/drivers/calibration.hpp"

#include <cmath>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

// The sample file stores doubles with 17 significant digits: a round trip is exact to ~1e-15.
constexpr double kRoundTripTolerance = 1e-12;
// Geometry in the sample was generated from degrees; 1e-9 is far below any physical meaning.
constexpr double kGeometryTolerance = 1e-9;
constexpr double kPi = 3.14159265358979323846;

// A one-rig calibration written by hand; @p fields replaces (or with "" drops) a top-level field
// of the rig, so each test breaks exactly one thing.
std::string OneRigYaml(const std::map<std::string, std::string>& fields) {
  std::map<std::string, std::string> rig = {
      {"id", "0"},
      {"name", "front"},
      {"image_width", "782"},
      {"image_height", "582"},
      {"left", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1], distortion: [] }"},
      {"right", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1], distortion: [] }"},
      {"R", "[1, 0, 0, 0, 1, 0, 0, 0, 1]"},
      {"T", "[-0.25, 0, 0]"},
      {"T_vehicle_rig", "[0, 0, 1, 1.4, -1, 0, 0, 0, 0, -1, 0, 1.2, 0, 0, 0, 1]"},
  };
  for (const auto& [key, value] : fields) rig[key] = value;
  std::string text = "%YAML:1.0\n---\nrigs:\n  -\n";
  for (const auto& [key, value] : rig) {
    if (!value.empty()) text += "    " + key + ": " + value + "\n";
  }
  return text;
}

std::string LoadError(const std::string& path) {
  try {
    Calibration::Load(path);
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "no error";
}

std::string YamlError(const std::map<std::string, std::string>& fields) {
  try {
    Calibration::FromYaml(OneRigYaml(fields), "hand.yaml");
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(CalibrationTest, SampleHasTheRoMoLayout) {
  const Calibration cal = Calibration::Load(SampleCalibrationPath());
  ASSERT_EQ(cal.rigs.size(), 6u);
  struct Mount {
    const char* name;
    double yaw_deg, x_m, y_m;
  };
  const Mount mounts[] = {{"front", 0, 1.4, 0},        {"left_front", 60, 0.7, 0.8},
                          {"left_rear", 120, -0.7, 0.8}, {"rear", 180, -1.4, 0},
                          {"right_rear", -120, -0.7, -0.8}, {"right_front", -60, 0.7, -0.8}};
  const double pitch = 15.0 * kPi / 180.0;
  for (int id = 0; id < 6; ++id) {
    SCOPED_TRACE(mounts[id].name);
    const RigCalibration& rig = cal.rig(id);
    EXPECT_EQ(rig.name, mounts[id].name);
    EXPECT_EQ(rig.width_px, 782);
    EXPECT_EQ(rig.height_px, 582);
    for (const CameraIntrinsics* cam : {&rig.left, &rig.right}) {
      EXPECT_DOUBLE_EQ(cam->K(0, 0), 400.0);
      EXPECT_DOUBLE_EQ(cam->K(1, 1), 400.0);
      EXPECT_DOUBLE_EQ(cam->K(0, 2), 390.5);
      EXPECT_DOUBLE_EQ(cam->K(1, 2), 290.5);
      ASSERT_GE(cam->distortion.size(), 2u);
      EXPECT_DOUBLE_EQ(cam->distortion[0], -0.02);
      EXPECT_DOUBLE_EQ(cam->distortion[1], 0.004);
      for (std::size_t i = 2; i < cam->distortion.size(); ++i) EXPECT_EQ(cam->distortion[i], 0.0);
    }
    EXPECT_TRUE(rig.R.isIdentity(kGeometryTolerance));
    EXPECT_NEAR((rig.T - Eigen::Vector3d(-0.25, 0, 0)).norm(), 0.0, kGeometryTolerance);
    EXPECT_NEAR(rig.baseline_m(), 0.25, kGeometryTolerance);

    // Independent of how the file was made: the optical axis (rig z) looks along the yaw,
    // 15 degrees below the horizon; rig x (image right) is horizontal, to the right of it;
    // rig y (image down) has a downward component.
    const double yaw = mounts[id].yaw_deg * kPi / 180.0;
    const Eigen::Matrix3d R = rig.T_vehicle_rig.linear();
    const Eigen::Vector3d axis(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                               -std::sin(pitch));
    const Eigen::Vector3d right(std::sin(yaw), -std::cos(yaw), 0.0);
    EXPECT_NEAR((R * Eigen::Vector3d::UnitZ() - axis).norm(), 0.0, kGeometryTolerance);
    EXPECT_NEAR((R * Eigen::Vector3d::UnitX() - right).norm(), 0.0, kGeometryTolerance);
    EXPECT_LT((R * Eigen::Vector3d::UnitY()).z(), 0.0);
    const Eigen::Vector3d t = rig.T_vehicle_rig.translation();
    EXPECT_NEAR((t - Eigen::Vector3d(mounts[id].x_m, mounts[id].y_m, 1.2)).norm(), 0.0,
                kGeometryTolerance);
  }
}

TEST(CalibrationTest, SampleCoversThreeHundredSixtyDegrees) {
  // Horizontal FOV 2*atan(cx/fx) ~ 88.9 deg per rig at 60 deg spacing: every azimuth is seen.
  const Calibration cal = Calibration::Load(SampleCalibrationPath());
  for (int azimuth_deg = -180; azimuth_deg < 180; ++azimuth_deg) {
    const double a = azimuth_deg * kPi / 180.0;
    // A point 10 m away on the ground around the vehicle.
    const Eigen::Vector3d p_vehicle(10 * std::cos(a), 10 * std::sin(a), 0.0);
    int seen_by = 0;
    for (const auto& rig : cal.rigs) {
      const Eigen::Vector3d p = rig.T_vehicle_rig.inverse() * p_vehicle;
      if (p.z() <= 0) continue;
      const double u = rig.left.K(0, 0) * p.x() / p.z() + rig.left.K(0, 2);
      const double v = rig.left.K(1, 1) * p.y() / p.z() + rig.left.K(1, 2);
      if (u >= 0 && u < rig.width_px && v >= 0 && v < rig.height_px) ++seen_by;
    }
    EXPECT_GE(seen_by, 1) << "azimuth " << azimuth_deg << " deg";
  }
}

TEST(CalibrationTest, YamlRoundTripIsExact) {
  const Calibration cal = Calibration::Load(SampleCalibrationPath());
  const Calibration back = Calibration::FromYaml(cal.ToYaml(), "memory");
  ASSERT_EQ(back.rigs.size(), cal.rigs.size());
  for (std::size_t i = 0; i < cal.rigs.size(); ++i) {
    const auto& a = cal.rigs[i];
    const auto& b = back.rigs[i];
    EXPECT_EQ(a.rig_id, b.rig_id);
    EXPECT_EQ(a.name, b.name);
    EXPECT_NEAR((a.left.K - b.left.K).norm(), 0.0, kRoundTripTolerance);
    EXPECT_NEAR((a.right.K - b.right.K).norm(), 0.0, kRoundTripTolerance);
    EXPECT_EQ(a.left.distortion, b.left.distortion);
    EXPECT_NEAR((a.R - b.R).norm(), 0.0, kRoundTripTolerance);
    EXPECT_NEAR((a.T - b.T).norm(), 0.0, kRoundTripTolerance);
    EXPECT_NEAR((a.T_vehicle_rig.matrix() - b.T_vehicle_rig.matrix()).norm(), 0.0,
                kRoundTripTolerance);
  }
}

TEST(CalibrationTest, SaveThenLoadGivesTheSameRigs) {
  test::ScratchDir dir;
  Calibration cal = Calibration::FromYaml(OneRigYaml({}), "hand.yaml");
  cal.rigs[0].left.distortion = {0.1, -0.01, 0.001, 0.002, 0.0001};
  cal.Save(dir / "saved.yaml");
  const Calibration back = Calibration::Load(dir / "saved.yaml");
  ASSERT_EQ(back.rigs.size(), 1u);
  EXPECT_EQ(back.rigs[0].left.distortion, cal.rigs[0].left.distortion);
  EXPECT_TRUE(back.rigs[0].right.distortion.empty());
  EXPECT_NEAR(back.rigs[0].T_vehicle_rig.translation().z(), 1.2, kRoundTripTolerance);
}

TEST(CalibrationTest, NegativeFocalLengthNamesFileFieldAndValue) {
  test::ScratchDir dir;
  Calibration cal = Calibration::Load(SampleCalibrationPath());
  cal.rigs[2].left.K(0, 0) = -3;
  const std::string path = dir / "romo_sample.yaml";
  test::WriteFile(path, cal.ToYaml());
  EXPECT_EQ(LoadError(path), path + ": rigs[2].left.K: fx = -3 must be > 0");
}

TEST(CalibrationTest, EachBrokenFieldIsNamed) {
  struct Case {
    std::map<std::string, std::string> fields;
    std::string expected;  // substring of the message
  };
  const Case cases[] = {
      {{{"R", "[1, 0.2, 0, 0, 1, 0, 0, 0, 1]"}}, "hand.yaml: rigs[0].R: rotation is not orthonormal"},
      {{{"R", "[-1, 0, 0, 0, 1, 0, 0, 0, 1]"}}, "hand.yaml: rigs[0].R: rotation has det = -1"},
      {{{"T", "[0, 0, 0]"}}, "hand.yaml: rigs[0].T: baseline |T| = 0 m"},
      {{{"image_width", "0"}}, "hand.yaml: rigs[0].image_width: width = 0 must be > 0"},
      {{{"image_height", "-5"}}, "hand.yaml: rigs[0].image_height: height = -5 must be > 0"},
      {{{"T_vehicle_rig", ""}}, "hand.yaml: rigs[0].T_vehicle_rig: missing"},
      {{{"T_vehicle_rig", "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]"}},
       "hand.yaml: rigs[0].T_vehicle_rig: expected a 4x4 matrix, got 1x12"},
      {{{"T_vehicle_rig", "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]"}},
       "rigs[0].T_vehicle_rig: last row must be (0, 0, 0, 1)"},
      {{{"id", "front"}}, "hand.yaml: rigs[0].id: expected an integer, got the text 'front'"},
      {{{"name", ""}}, "hand.yaml: rigs[0].name: missing"},
      {{{"left", ""}}, "hand.yaml: rigs[0].left: missing"},
      {{{"right", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1], distortion: [0.1, 0.2, 0.3] }"}},
       "hand.yaml: rigs[0].right.distortion: 3 coefficients"},
      {{{"right", "{ K: [400, 0, 990.5, 0, 400, 290.5, 0, 0, 1], distortion: [] }"}},
       "hand.yaml: rigs[0].right.K: cx = 990.5 must lie in [0, width = 782]"},
      {{{"left", "{ K: [400, 0, 390.5, 0, 0, 290.5, 0, 0, 1], distortion: [] }"}},
       "hand.yaml: rigs[0].left.K: fy = 0 must be > 0"},
      {{{"left", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1] }"}},
       "hand.yaml: rigs[0].left.distortion: missing"},
      {{{"left", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, .nan], distortion: [] }"}},
       "hand.yaml: rigs[0].left.K: element (2,2) = nan is not finite"},
  };
  for (const auto& c : cases) {
    const std::string message = YamlError(c.fields);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected '" << c.expected << "' in '" << message << "'";
  }
}

TEST(CalibrationTest, DuplicateRigIdsAreRejected) {
  Calibration cal = Calibration::Load(SampleCalibrationPath());
  cal.rigs[4].rig_id = 1;
  try {
    cal.Validate("dup.yaml");
    FAIL() << "duplicate id accepted";
  } catch (const romo::Error& e) {
    EXPECT_STREQ(e.what(), "dup.yaml: rigs[4].id: duplicate rig id 1");
  }
}

TEST(CalibrationTest, MissingAndGarbledFilesGiveClearErrors) {
  test::ScratchDir dir;
  EXPECT_EQ(LoadError(dir / "none.yaml"), dir / "none.yaml" + ": calibration file not found");

  test::WriteFile(dir / "garbled.yaml", "%YAML:1.0\n---\nrigs: [ {id: 0, name: \n  ]]] : :\n");
  EXPECT_NE(LoadError(dir / "garbled.yaml").find(dir / "garbled.yaml"), std::string::npos);

  test::WriteFile(dir / "norigs.yaml", "%YAML:1.0\n---\ncameras: 3\n");
  EXPECT_EQ(LoadError(dir / "norigs.yaml"), dir / "norigs.yaml" + ": rigs: missing");

  test::WriteFile(dir / "empty_rigs.yaml", "%YAML:1.0\n---\nrigs: []\n");
  EXPECT_EQ(LoadError(dir / "empty_rigs.yaml"), dir / "empty_rigs.yaml" + ": rigs: no rigs");

  EXPECT_THROW(Calibration::FromYaml("", "ROMO_CALIBRATION"), romo::Error);
  EXPECT_THROW(Calibration::FromYaml("\x01\x02 not yaml {{{", "ROMO_CALIBRATION"), romo::Error);
}

TEST(CalibrationTest, UnknownRigIdThrows) {
  const Calibration cal = Calibration::Load(SampleCalibrationPath());
  EXPECT_THROW(cal.rig(6), romo::Error);
}

}  // namespace
}  // namespace romo::drivers
