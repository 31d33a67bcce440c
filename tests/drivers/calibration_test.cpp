#include "romo/drivers/calibration.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
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


// Bit-for-bit: numbers are written in shortest round-trip form and read back exactly.
void ExpectSameCalibration(const Calibration& a, const Calibration& b) {
  ASSERT_EQ(a.rigs.size(), b.rigs.size());
  for (std::size_t i = 0; i < a.rigs.size(); ++i) {
    SCOPED_TRACE("rig " + std::to_string(i));
    const RigCalibration& x = a.rigs[i];
    const RigCalibration& y = b.rigs[i];
    EXPECT_EQ(x.rig_id, y.rig_id);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width_px, y.width_px);
    EXPECT_EQ(x.height_px, y.height_px);
    EXPECT_EQ(x.left.K, y.left.K);
    EXPECT_EQ(x.right.K, y.right.K);
    EXPECT_EQ(x.left.distortion, y.left.distortion);
    EXPECT_EQ(x.right.distortion, y.right.distortion);
    EXPECT_EQ(x.R, y.R);
    EXPECT_EQ(x.T, y.T);
    EXPECT_EQ(x.T_vehicle_rig.matrix(), y.T_vehicle_rig.matrix());
  }
}

Calibration SaveAndLoad(const Calibration& cal) {
  test::ScratchDir dir;
  cal.Save(dir / "saved.yaml");
  return Calibration::Load(dir / "saved.yaml");
}

TEST(CalibrationTest, SampleLoadSaveLoadIsBitExact) {
  const Calibration cal = Calibration::Load(SampleCalibrationPath());
  ASSERT_EQ(cal.rigs.size(), 6u);
  // Spot values as the file spells them (17 digits), compared exactly.
  EXPECT_EQ(cal.rigs[0].T_vehicle_rig(0, 1), -2.5881904510252074e-01);
  EXPECT_EQ(cal.rigs[0].T_vehicle_rig(1, 0), -1.0);
  EXPECT_EQ(cal.rigs[0].left.distortion[1], 4.0000000000000001e-03);
  EXPECT_EQ(cal.rigs[5].name, "right_front");
  ExpectSameCalibration(cal, SaveAndLoad(cal));
  ExpectSameCalibration(cal, Calibration::FromYaml(cal.ToYaml(), "memory"));
}

TEST(CalibrationTest, ReadsWhatOpenCvReadsFromTheSample) {
  // The reader is not cv::FileStorage (it hangs on some inputs); on the shipped file both must
  // give the same numbers.
  const std::string path = SampleCalibrationPath();
  const Calibration cal = Calibration::Load(path);
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  int index = 0;
  for (const auto& node : fs["rigs"]) {
    const RigCalibration& rig = cal.rigs[index++];
    EXPECT_EQ(static_cast<int>(node["id"]), rig.rig_id);
    EXPECT_EQ(static_cast<std::string>(node["name"]), rig.name);
    cv::Mat K, R, T, pose;
    node["left"]["K"] >> K;
    node["R"] >> R;
    node["T"] >> T;
    node["T_vehicle_rig"] >> pose;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(K.at<double>(r, c), rig.left.K(r, c));
        EXPECT_EQ(R.at<double>(r, c), rig.R(r, c));
      }
      EXPECT_EQ(T.at<double>(r, 0), rig.T(r));
    }
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) EXPECT_EQ(pose.at<double>(r, c), rig.T_vehicle_rig(r, c));
    }
    std::vector<double> distortion;
    node["right"]["distortion"] >> distortion;
    EXPECT_EQ(distortion, rig.right.distortion);
  }
  EXPECT_EQ(index, 6);
}

TEST(CalibrationTest, OpenCvReadsWhatSaveWrites) {
  // Saved files keep the FileStorage layout, so OpenCV tools still read them.
  Calibration cal = Calibration::Load(SampleCalibrationPath());
  cal.rigs[1].left.distortion = {0.1, -0.01, 0.001, 0.002};
  cv::FileStorage fs(cal.ToYaml(), cv::FileStorage::READ | cv::FileStorage::MEMORY);
  ASSERT_TRUE(fs.isOpened());
  const cv::FileNode rig = fs["rigs"][1];
  EXPECT_EQ(static_cast<std::string>(rig["name"]), "left_front");
  cv::Mat pose;
  rig["T_vehicle_rig"] >> pose;
  ASSERT_EQ(pose.rows, 4);
  ASSERT_EQ(pose.cols, 4);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ(pose.at<double>(r, c), cal.rigs[1].T_vehicle_rig(r, c));
  }
  std::vector<double> distortion;
  rig["left"]["distortion"] >> distortion;
  EXPECT_EQ(distortion, cal.rigs[1].left.distortion);
}

TEST(CalibrationTest, CalibrationInARecordingLoadsSavesAndLoadsBitExact) {
  // A recording carries the calibration as YAML text in its first event: what the log reader
  // parses from it equals the file it came from and saves and loads back bit for bit. (The
  // recordings under fuzz/corpus are generated, not in the repository, so this writes its own.)
  test::ScratchDir dir;
  const Calibration sample = Calibration::Load(SampleCalibrationPath());
  {
    LogWriter writer(dir / "calibrated.lcmlog");
    writer.WriteCalibration(sample, 0);
    writer.Close();
  }
  LogReader reader(dir / "calibrated.lcmlog");
  EXPECT_FALSE(reader.Next().has_value());  // a calibration and no frame set
  ASSERT_NE(reader.calibration(), nullptr);
  ExpectSameCalibration(sample, *reader.calibration());
  ExpectSameCalibration(*reader.calibration(), SaveAndLoad(*reader.calibration()));
}

TEST(CalibrationTest, OddNamesRoundTrip) {
  Calibration cal = Calibration::FromYaml(OneRigYaml({}), "hand.yaml");
  for (const std::string name : {"null", "12", " padded ", "a: b", "quote\" and \\ back", "#x",
                                 "'single'", "-", "true"}) {
    SCOPED_TRACE(name);
    cal.rigs[0].name = name;
    EXPECT_EQ(SaveAndLoad(cal).rigs[0].name, name);
  }
}

TEST(CalibrationTest, NonPrintableNameIsRejected) {
  Calibration cal = Calibration::FromYaml(OneRigYaml({}), "hand.yaml");
  cal.rigs[0].name = "fr\x01nt";
  EXPECT_EQ(test::ErrorOf([&] { cal.Validate("cal.yaml"); }),
            "cal.yaml: rigs[0].name: byte 2 is 0x01; names are printable ASCII");
}

TEST(CalibrationTest, OpenCvSpellingsAreTypedAsOpenCvTypesThem) {
  // OpenCV writes NaN as .Nan; a quoted number is text; dt: f stores floats.
  EXPECT_NE(YamlError({{"left", "{ K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, .Nan], distortion: [] }"}})
                .find("hand.yaml: rigs[0].left.K: element (2,2) = nan is not finite"),
            std::string::npos);
  EXPECT_EQ(YamlError({{"id", "\"0\""}}),
            "hand.yaml: rigs[0].id: expected an integer, got the text '0'");
  EXPECT_EQ(YamlError({{"name", "7"}}), "hand.yaml: rigs[0].name: expected text, got an integer");
  EXPECT_EQ(YamlError({{"T", "!!opencv-matrix { rows: 3, cols: 1, dt: d, data: [ -0.25, 0 ] }"}}),
            "hand.yaml: rigs[0].T: opencv-matrix rows x cols = 3x1 does not match its 2 numbers");
  // Found by fuzzing: a missing key threw yaml-cpp's InvalidNode instead of naming the field.
  EXPECT_EQ(YamlError({{"T", "!!opencv-matrix { rows: 3, dt: d, data: [ -0.25, 0, 0 ] }"}}),
            "hand.yaml: rigs[0].T.cols: expected a count, got missing");
  EXPECT_EQ(YamlError({{"T", "!!opencv-matrix { rows: 3, cols: 1, dt: 3d, data: [ -0.25, 0, 0 ] }"}}),
            "hand.yaml: rigs[0].T.dt: expected one of u, c, w, s, i, f, d, got the text '3d'");
  const Calibration cal = Calibration::FromYaml(
      OneRigYaml({{"T", "!!opencv-matrix { rows: 3, cols: 1, dt: f, data: [ -0.1, 0, 0 ] }"}}),
      "hand.yaml");
  EXPECT_EQ(cal.rigs[0].T.x(), static_cast<double>(-0.1f));
}

TEST(CalibrationTest, DocumentThatHungOpenCvFailsFastNamingTheLine) {
  // fuzz/regressions/calibration_yaml/opencv_4.6_yaml_parser_hung: OpenCV 4.6's FileStorage
  // spun on it for > 90 s.
  const std::string text =
      "%YAML:1.000000000000000e+00, 0., 0., 00000000000e+00, 0., 0., 000000000   -\n"
      "      id: 2\n  00   -\n      id: 2\n      na: #39\n [ -3 ";
  ASSERT_EQ(text.size(), 129u);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = test::ErrorOf([&] { Calibration::FromYaml(text, "ROMO_CALIBRATION"); });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(error, "ROMO_CALIBRATION: not a valid YAML calibration: line 4, column 9: illegal map value");
  constexpr double kMaxParseS = 1.0;  // it takes microseconds; 1 s allows a loaded CI machine
  EXPECT_LT(seconds, kMaxParseS);
}

TEST(CalibrationTest, AliasedHugeMapsAreRefusedBeforeTheyAreSearched) {
  // YAML aliases repeat one node for free; each key lookup scans its map. 60000 aliases of a
  // 50000-key rig (< 1 MiB) kept the reader busy for minutes before the counts were capped.
  std::string junk;
  for (int i = 0; i < 40; ++i) junk += "k" + std::to_string(i) + ": 0, ";
  const std::string rig = "{ " + junk +
                          "id: 0, name: front, image_width: 782, image_height: 582, "
                          "left: { K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1], distortion: [] }, "
                          "right: { K: [400, 0, 390.5, 0, 400, 290.5, 0, 0, 1], distortion: [] }, "
                          "R: [1, 0, 0, 0, 1, 0, 0, 0, 1], T: [-0.25, 0, 0], "
                          "T_vehicle_rig: [0, 0, 1, 1.4, -1, 0, 0, 0, 0, -1, 0, 1.2, 0, 0, 0, 1] }";
  std::string aliases;
  for (int i = 0; i < 1000; ++i) aliases += std::string(i ? ", " : "") + "*a";
  EXPECT_EQ(test::ErrorOf([&] {
              Calibration::FromYaml("base: &a " + rig + "\nrigs: [" + aliases + "]\n", "alias.yaml");
            }),
            "alias.yaml: rigs: 1000 rigs, more than the 64 a calibration may hold");
  EXPECT_EQ(test::ErrorOf([&] { Calibration::FromYaml("base: &a " + rig + "\nrigs: [*a]\n", "alias.yaml"); }),
            "alias.yaml: rigs[0]: a map of 49 keys, more than the 32 any calibration map has");
  std::string long_list = "[1";
  for (int i = 0; i < 100; ++i) long_list += ", 0";
  EXPECT_EQ(YamlError({{"R", long_list + "]"}}),
            "hand.yaml: rigs[0].R: 101 numbers, too many for a 3x3 matrix");
}

TEST(CalibrationTest, DeepNestingIsRefusedNamingTheDepth) {
  EXPECT_EQ(test::ErrorOf([] { Calibration::FromYaml(std::string(5000, '['), "deep.yaml"); }),
            "deep.yaml: not a valid YAML calibration: line 1, column 1: nested 500 levels deep, "
            "deeper than the YAML reader allows");
}

TEST(CalibrationTest, OversizedTextIsRefusedBeforeParsing) {
  const std::string text = "%YAML:1.0\n---\nrigs: [" + std::string(2 << 20, ' ') + "]\n";
  EXPECT_EQ(test::ErrorOf([&] { Calibration::FromYaml(text, "big.yaml"); }),
            "big.yaml: calibration text is " + std::to_string(text.size()) +
                " bytes, over the 1048576 any calibration needs");
}

}  // namespace
}  // namespace romo::drivers
