// `romo record` end to end: the built binary, real sources, real files.
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "romo/drivers/recording.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;

bool Exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

int CountSets(const std::string& path) {
  LogReader reader(path);
  int count = 0;
  while (reader.Next()) ++count;
  return count;
}

// A log of @p count one-rig frame sets with the sample calibration.
void WriteInputLog(const std::string& path, int count) {
  LogWriter writer(path);
  writer.WriteCalibration(Calibration::Load(SampleCalibrationPath()), kStartNs);
  for (int k = 0; k < count; ++k) {
    FrameSet set;
    set.sequence = static_cast<std::uint64_t>(k);
    set.stamp_ns = kStartNs + k * 100'000'000LL;
    StereoFrame stereo;
    stereo.left.image = Image::Allocate(PixelFormat::kMono8, 64, 48);
    stereo.right.image = Image::Allocate(PixelFormat::kMono8, 64, 48);
    stereo.left.image.data[static_cast<std::size_t>(k)] = 200;
    set.stereo.push_back(std::move(stereo));
    writer.Write(set);
  }
}

TEST(RecordCliTest, RecordsAnRgbdFolder) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/kinect_seq");
  test::ScratchDir dir;
  const auto result = test::RunRomo("record --source rgbd://" + test::SharedData("rgbd/kinect_seq") +
                                    " --out " + (dir / "k.lcmlog") + " --frames 3 --png");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("recorded 3 frame sets"), std::string::npos) << result.out;
  EXPECT_NE(result.err.find("record"), std::string::npos);  // the progress line
  EXPECT_FALSE(Exists(dir / "k.lcmlog.partial"));
  LogReader reader(dir / "k.lcmlog");
  int count = 0;
  while (auto set = reader.Next()) {
    ASSERT_TRUE(set->rgbd);
    EXPECT_EQ(set->rgbd->rgb.width, 640);
    ++count;
  }
  EXPECT_EQ(count, 3);
}

TEST(RecordCliTest, CalibrationOfTheSourceIsWrittenFirst) {
  test::ScratchDir dir;
  WriteInputLog(dir / "in.lcmlog", 4);
  const auto result =
      test::RunRomo("record --source log://" + (dir / "in.lcmlog") + " --out " + (dir / "out.lcmlog"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto events = ReadAllEvents(dir / "out.lcmlog", nullptr);
  ASSERT_EQ(events.size(), 5u);
  EXPECT_EQ(events[0].channel, kCalibrationChannel);
  EXPECT_EQ(events[0].timestamp_us, kStartNs / 1000);
  LogReader reader(dir / "out.lcmlog");
  ASSERT_NE(reader.calibration(), nullptr);
  EXPECT_EQ(reader.calibration()->rigs.size(), 6u);
}

TEST(RecordCliTest, BadSourcesExitNonZeroWithAClearMessage) {
  test::ScratchDir dir;
  auto result = test::RunRomo("record --source tape://x --out " + (dir / "o.lcmlog"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("unknown source URI scheme 'tape'"), std::string::npos) << result.err;
  result = test::RunRomo("record --source rgbd://" + (dir / "none") + " --out " + (dir / "o.lcmlog"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("RGB-D folder not found"), std::string::npos) << result.err;
  result = test::RunRomo("record --source kinect://0 --out " + (dir / "o.lcmlog"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("no Kinect found at index 0"), std::string::npos) << result.err;
  EXPECT_FALSE(Exists(dir / "o.lcmlog.partial"));
  EXPECT_NE(test::RunRomo("record --out " + (dir / "o.lcmlog")).exit_code, 0);  // --source required
}

TEST(RecordCliTest, SourceFailureMidRunKeepsEveryCompletedFrameSet) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/tum_pair");
  test::ScratchDir dir;
  const std::string data = test::SharedData("rgbd/tum_pair");
  // Frames 1 and 2 are real; frame 3's depth image is garbage bytes.
  for (const char* name : {"1.png", "1_depth.png", "2.png", "2_depth.png"}) {
    ASSERT_EQ(::symlink((data + "/" + name).c_str(), (dir / name).c_str()), 0);
  }
  ASSERT_EQ(::symlink((data + "/1.png").c_str(), (dir / "3.png").c_str()), 0);
  test::WriteFile(dir / "3_depth.png", "this is not a PNG file");
  const auto result = test::RunRomo("record --source rgbd://" + dir.path() + " --out " + (dir / "o.lcmlog"));
  EXPECT_EQ(result.exit_code, 3) << result.err;
  EXPECT_NE(result.err.find("source failed"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("stopped after 2 frame sets; all 2 kept"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("3_depth.png"), std::string::npos) << result.err;
  EXPECT_EQ(CountSets(dir / "o.lcmlog"), 2);
}

TEST(RecordCliTest, SigintClosesTheFileCleanly) {
  test::ScratchDir dir;
  WriteInputLog(dir / "in.lcmlog", 5);
  // An endless source (looping at real time, 10 Hz) stopped by SIGINT after ~1 s.
  const std::string romo = test::RomoBinary();
  const auto result = test::RunShell(
      "'" + romo + "' record --source 'log://" + (dir / "in.lcmlog") + "?loop=1&pacing=realtime' --out '" +
      (dir / "out.lcmlog") + "' > '" + (dir / "stdout.txt") + "' 2>&1 & pid=$!; " +
      // The .partial file exists once the handler is installed; then record for ~1 s.
      "for i in $(seq 300); do [ -e '" + (dir / "out.lcmlog.partial") + "' ] && break; sleep 0.1; done; " +
      "sleep 1; kill -INT $pid; wait $pid; echo rc=$?");
  EXPECT_NE(result.out.find("rc=0"), std::string::npos) << result.out << result.err;
  EXPECT_NE(test::ReadFile(dir / "stdout.txt").find("(interrupted)"), std::string::npos)
      << test::ReadFile(dir / "stdout.txt");
  EXPECT_FALSE(Exists(dir / "out.lcmlog.partial"));
  const int sets = CountSets(dir / "out.lcmlog");
  EXPECT_GE(sets, 3);  // ~10 in one second at 10 Hz; 3 leaves room for a loaded machine
  std::int64_t truncated_at = 0;
  ReadAllEvents(dir / "out.lcmlog", &truncated_at);
  EXPECT_EQ(truncated_at, -1);
}

}  // namespace
}  // namespace romo::drivers
