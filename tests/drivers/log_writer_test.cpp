#include <cstdio>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo_lcm/stereo_frame_t.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;

bool Exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

std::int64_t FileSize(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<std::int64_t>(st.st_size) : -1;
}

// One rig of 12-bit mono images with a smooth ramp (what PNG compresses well).
FrameSet RampFrameSet(std::uint64_t k) {
  FrameSet set;
  set.sequence = k;
  set.stamp_ns = kStartNs + static_cast<std::int64_t>(k) * 100'000'000;
  StereoFrame stereo;
  stereo.rig_id = 2;
  for (CameraFrame* cam : {&stereo.left, &stereo.right}) {
    cam->image = Image::Allocate(PixelFormat::kMono16, 782, 582);
    for (int y = 0; y < 582; ++y) {
      auto* row = reinterpret_cast<std::uint16_t*>(cam->image.row(y));
      for (int x = 0; x < 782; ++x) row[x] = static_cast<std::uint16_t>((x + y + k) & 0x0FFF);
    }
    cam->stamp_ns = set.stamp_ns;
  }
  set.stereo.push_back(std::move(stereo));
  return set;
}

TEST(LogWriterTest, WritesPartialFileAndRenamesItOnClose) {
  test::ScratchDir dir;
  const std::string path = dir / "run.lcmlog";
  LogWriter writer(path);
  writer.Write(RampFrameSet(0));
  EXPECT_TRUE(Exists(path + ".partial"));
  EXPECT_FALSE(Exists(path));
  writer.Close();
  EXPECT_TRUE(Exists(path));
  EXPECT_FALSE(Exists(path + ".partial"));
  writer.Close();  // idempotent
  EXPECT_TRUE(Exists(path));
  EXPECT_THROW(writer.Write(RampFrameSet(1)), romo::Error);
}

TEST(LogWriterTest, APartialLeftByAKilledWriterIsKeptNotOverwritten) {
  test::ScratchDir dir;
  const std::string path = dir / "run.lcmlog";
  std::string killed_bytes;
  for (int run = 1; run <= 2; ++run) {
    {
      // What SIGKILL leaves: the .partial with every flushed set, never renamed.
      LogWriter killed(path);
      killed.Write(RampFrameSet(static_cast<std::uint64_t>(run)));
      killed_bytes = test::ReadFile(path + ".partial");
      ASSERT_EQ(std::rename((path + ".partial").c_str(), (dir / "aside").c_str()), 0);
    }
    ASSERT_EQ(std::rename((dir / "aside").c_str(), (path + ".partial").c_str()), 0);
    LogWriter next(path);
    const std::string kept = dir / ("run.interrupted-" + std::to_string(run) + ".lcmlog");
    EXPECT_EQ(next.kept_interrupted(), kept);
    EXPECT_EQ(test::ReadFile(kept), killed_bytes);
    std::int64_t cut_at = 0;
    EXPECT_EQ(ReadAllEvents(kept, &cut_at).size(), 1u) << "one set of one rig";
    EXPECT_EQ(cut_at, -1);
    next.Close();
  }
  EXPECT_TRUE(Exists(path));
  LogWriter clean(dir / "clean.lcmlog");
  EXPECT_EQ(clean.kept_interrupted(), "");
}

TEST(LogWriterTest, DestructorClosesTheFile) {
  test::ScratchDir dir;
  { LogWriter writer(dir / "run.lcmlog"); }
  EXPECT_TRUE(Exists(dir / "run.lcmlog"));
}

TEST(LogWriterTest, EveryCompletedEventIsOnDiskBeforeClose) {
  test::ScratchDir dir;
  LogWriter writer(dir / "run.lcmlog");
  for (std::uint64_t k = 0; k < 3; ++k) writer.Write(RampFrameSet(k));
  EXPECT_EQ(writer.events_written(), 3u);
  EXPECT_EQ(FileSize(dir / "run.lcmlog.partial"), static_cast<std::int64_t>(writer.bytes_written()));
  std::int64_t truncated_at = 0;
  EXPECT_EQ(ReadAllEvents(dir / "run.lcmlog.partial", &truncated_at).size(), 3u);
  EXPECT_EQ(truncated_at, -1);
}

TEST(LogWriterTest, LcmsOwnLogReaderReadsTheFile) {
  test::ScratchDir dir;
  {
    LogWriter writer(dir / "run.lcmlog");
    writer.WriteCalibration(Calibration::Load(SampleCalibrationPath()), kStartNs);
    writer.Write(RampFrameSet(0));
    writer.WriteRaw("OTHER", kStartNs + 1000, "abc", 3);
  }
  lcm::LogFile log(dir / "run.lcmlog", "r");
  ASSERT_TRUE(log.good());
  std::vector<std::string> channels;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    channels.push_back(event->channel);
    if (event->channel == StereoChannel(2)) {
      romo_lcm::stereo_frame_t msg;
      ASSERT_GT(msg.decode(event->data, 0, event->datalen), 0);
      EXPECT_EQ(msg.rig_id, 2);
      EXPECT_EQ(msg.left.width, 782);
      EXPECT_EQ(event->timestamp, kStartNs / 1000);
    }
  }
  EXPECT_EQ(channels, (std::vector<std::string>{"ROMO_CALIBRATION", "ROMO_STEREO_RIG2", "OTHER"}));
}

TEST(LogWriterTest, PngIsSmallerThanRawForSmoothImages) {
  test::ScratchDir dir;
  std::uint64_t raw_bytes = 0;
  std::uint64_t png_bytes = 0;
  {
    LogWriter raw(dir / "raw.lcmlog", ImageEncoding::kRaw);
    LogWriter png(dir / "png.lcmlog", ImageEncoding::kPng);
    raw.Write(RampFrameSet(0));
    png.Write(RampFrameSet(0));
    raw_bytes = raw.bytes_written();
    png_bytes = png.bytes_written();
  }
  // Two 782x582 16-bit images: 910 KB raw; a ramp compresses by far more than 2x.
  EXPECT_GT(raw_bytes, 2 * 782u * 582u * 2u);
  EXPECT_LT(png_bytes * 2, raw_bytes);
  EXPECT_EQ(FileSize(dir / "png.lcmlog"), static_cast<std::int64_t>(png_bytes));
}

TEST(LogWriterTest, BadPathsAndBadFramesThrow) {
  test::ScratchDir dir;
  try {
    LogWriter writer(dir / "missing_folder/run.lcmlog");
    FAIL() << "created a file in a missing folder";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing_folder/run.lcmlog.partial: cannot create"),
              std::string::npos)
        << e.what();
  }
  LogWriter writer(dir / "run.lcmlog");
  FrameSet bad = RampFrameSet(0);
  bad.stereo[0].left.image.data.resize(10);  // buffer disagrees with its size
  EXPECT_THROW(writer.Write(bad), romo::Error);
  EXPECT_EQ(writer.events_written(), 0u);  // nothing half-written
  EXPECT_THROW(writer.WriteRaw("", kStartNs, "x", 1), romo::Error);
}

}  // namespace
}  // namespace romo::drivers
