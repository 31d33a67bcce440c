// `romo info` end to end on logs with known content.
#include <regex>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include "romo/drivers/recording.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;
// The JSON prints 6 decimals; rates from microsecond stamps are exact to ~1e-6 relative.
constexpr double kJsonTolerance = 1e-5;

// 10 Hz stereo on rig 1 for sequences 0..9 without 5 (one drop), 2.5 Hz ground truth (0, 0.4, 0.8 s).
std::uint64_t WriteKnownLog(const std::string& path) {
  LogWriter writer(path);
  writer.WriteCalibration(Calibration::Load(SampleCalibrationPath()), kStartNs);
  for (int k = 0; k < 10; ++k) {
    if (k == 5) continue;
    FrameSet set;
    set.sequence = static_cast<std::uint64_t>(k);
    set.stamp_ns = kStartNs + k * 100'000'000LL;
    StereoFrame stereo;
    stereo.rig_id = 1;
    stereo.left.image = Image::Allocate(PixelFormat::kMono8, 16, 8);
    stereo.right.image = Image::Allocate(PixelFormat::kMono8, 16, 8);
    set.stereo.push_back(std::move(stereo));
    writer.Write(set);
    if (k % 4 == 0) writer.WriteRaw("GROUND_TRUTH", set.stamp_ns, "gt", 2);
  }
  writer.Close();
  return writer.bytes_written();
}

double NumberAfter(const std::string& json, const std::string& key, std::size_t from = 0) {
  const auto at = json.find("\"" + key + "\":", from);
  EXPECT_NE(at, std::string::npos) << key << " in " << json;
  return at == std::string::npos ? -1 : std::stod(json.substr(at + key.size() + 3));
}

TEST(InfoCliTest, JsonSummaryHasTheDocumentedKeysAndValues) {
  test::ScratchDir dir;
  WriteKnownLog(dir / "run.lcmlog");
  const auto result = test::RunRomo("info --json " + (dir / "run.lcmlog"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string& json = result.out;
  EXPECT_NE(json.find("\"file\":\"" + (dir / "run.lcmlog") + "\""), std::string::npos) << json;
  EXPECT_NEAR(NumberAfter(json, "span_s"), 0.9, kJsonTolerance);
  EXPECT_NE(json.find("\"truncated\":false"), std::string::npos);

  const auto rig = json.find("\"name\":\"ROMO_STEREO_RIG1\"");
  ASSERT_NE(rig, std::string::npos) << json;
  EXPECT_EQ(json.find("\"type\":\"romo_lcm.stereo_frame_t\"", rig), json.find("\"type\"", rig));
  EXPECT_EQ(NumberAfter(json, "count", rig), 9);
  EXPECT_NEAR(NumberAfter(json, "rate_hz", rig), 8 / 0.9, kJsonTolerance);
  EXPECT_EQ(NumberAfter(json, "dropped", rig), 1);

  const auto cal = json.find("\"name\":\"ROMO_CALIBRATION\"");
  ASSERT_NE(cal, std::string::npos);
  EXPECT_EQ(json.find("\"type\":\"romo_lcm.calibration_t\"", cal), json.find("\"type\"", cal));
  EXPECT_EQ(NumberAfter(json, "count", cal), 1);
  EXPECT_EQ(NumberAfter(json, "rate_hz", cal), 0);

  const auto gt = json.find("\"name\":\"GROUND_TRUTH\"");
  ASSERT_NE(gt, std::string::npos);
  EXPECT_EQ(json.find("\"type\":\"unknown\"", gt), json.find("\"type\"", gt));
  EXPECT_EQ(NumberAfter(json, "count", gt), 3);
  EXPECT_NEAR(NumberAfter(json, "rate_hz", gt), 2 / 0.8, kJsonTolerance);
  // The largest stereo gap is the dropped frame: 200 ms.
  EXPECT_NE(json.find("\"largest_gaps_s\":[0.200000", rig), std::string::npos) << json;
}

TEST(InfoCliTest, TextSummaryListsChannels) {
  test::ScratchDir dir;
  WriteKnownLog(dir / "run.lcmlog");
  const auto result = test::RunRomo("info " + (dir / "run.lcmlog"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(std::regex_search(result.out, std::regex("ROMO_STEREO_RIG1 +romo_lcm.stereo_frame_t +9 ")))
      << result.out;
  EXPECT_NE(result.out.find("span 0.900 s"), std::string::npos) << result.out;
}

TEST(InfoCliTest, TruncatedLogIsReportedWithEveryCompleteEventCounted) {
  test::ScratchDir dir;
  const std::uint64_t bytes = WriteKnownLog(dir / "run.lcmlog");
  ASSERT_EQ(::truncate((dir / "run.lcmlog").c_str(), static_cast<off_t>(bytes - 1)), 0);
  const auto result = test::RunRomo("info --json " + (dir / "run.lcmlog"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("\"truncated\":true"), std::string::npos) << result.out;
  // The last event (rig 1, sequence 9) is cut: 8 stereo events remain.
  EXPECT_EQ(NumberAfter(result.out, "count", result.out.find("ROMO_STEREO_RIG1")), 8);
}

TEST(InfoCliTest, GarbageAndMissingFilesExitWithBadInput) {
  test::ScratchDir dir;
  test::WriteFile(dir / "garbage.lcmlog", "GIF89a definitely not a log");
  auto result = test::RunRomo("info " + (dir / "garbage.lcmlog"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("not an LCM log file"), std::string::npos) << result.err;
  result = test::RunRomo("info " + (dir / "missing.lcmlog"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("recording not found"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace romo::drivers
