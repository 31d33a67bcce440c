#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo_lcm/calibration_t.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

using ::romo::test::ErrorOf;

constexpr std::int64_t kFramePeriodNs = 100'000'000;  // 10 Hz, the vehicle's camera rate
constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;
// Poses pass through a quaternion: doubles survive to ~1e-15, 1e-12 leaves room for rounding.
constexpr double kPoseTolerance = 1e-12;

Image RandomImage(PixelFormat format, int width, int height, std::mt19937* rng) {
  Image image = Image::Allocate(format, width, height);
  std::uniform_int_distribution<int> byte(0, 255);
  for (auto& b : image.data) b = static_cast<std::uint8_t>(byte(*rng));
  if (format == PixelFormat::kMono16) {
    // 12-bit camera samples, as the RoMo cameras deliver.
    auto* samples = reinterpret_cast<std::uint16_t*>(image.data.data());
    for (std::size_t i = 0; i < image.data.size() / 2; ++i) samples[i] &= 0x0FFF;
  }
  return image;
}

// Frame set @p k: two rigs (odd widths, mono8 and mono16), RGB-D, vehicle state, GNSS.
FrameSet MakeFrameSet(std::uint64_t k, std::mt19937* rng) {
  FrameSet set;
  set.sequence = k;
  set.stamp_ns = kStartNs + static_cast<std::int64_t>(k) * kFramePeriodNs;
  for (int rig : {0, 3}) {
    StereoFrame stereo;
    stereo.rig_id = rig;
    const PixelFormat format = rig == 0 ? PixelFormat::kMono8 : PixelFormat::kMono16;
    stereo.left.image = RandomImage(format, 37, 21, rng);
    stereo.right.image = RandomImage(format, 37, 21, rng);
    stereo.left.stamp_ns = set.stamp_ns + 17;
    stereo.right.stamp_ns = set.stamp_ns + 23;
    stereo.left.sequence = stereo.right.sequence = 1000 + k;
    stereo.left.camera_id = "cam" + std::to_string(2 * rig);
    stereo.right.camera_id = "cam" + std::to_string(2 * rig + 1);
    set.stereo.push_back(std::move(stereo));
  }
  RgbdFrame rgbd;
  rgbd.rgb = RandomImage(PixelFormat::kRgb8, 31, 17, rng);
  rgbd.depth = RandomImage(PixelFormat::kMono16, 31, 17, rng);
  rgbd.depth_scale_m = 0.0002;
  rgbd.stamp_ns = set.stamp_ns + 5;
  rgbd.sequence = k;
  set.rgbd = std::move(rgbd);
  VehicleState state;
  state.stamp_ns = set.stamp_ns;
  state.T_world_vehicle.linear() =
      Eigen::AngleAxisd(0.1 * static_cast<double>(k), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  state.T_world_vehicle.translation() = Eigen::Vector3d(1.5 * k, -2.0, 0.25);
  state.speed_mps = 3.5;
  state.yaw_rate_radps = -0.2;
  set.vehicle = state;
  GnssFix fix;
  fix.stamp_ns = set.stamp_ns + 1;
  fix.latitude_deg = 48.08 + 1e-6 * k;
  fix.longitude_deg = 11.28;
  fix.altitude_m = 590.0;
  fix.horizontal_sigma_m = 0.02;
  fix.valid = true;
  set.gnss = fix;
  return set;
}

void ExpectSameImage(const Image& a, const Image& b) {
  ASSERT_EQ(a.format, b.format);
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  const int row_bytes = a.width * BytesPerPixel(a.format);
  for (int y = 0; y < a.height; ++y) {
    ASSERT_EQ(0, std::memcmp(a.row(y), b.row(y), static_cast<std::size_t>(row_bytes))) << "row " << y;
  }
}

void ExpectSameFrameSet(const FrameSet& a, const FrameSet& b) {
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  ASSERT_EQ(a.stereo.size(), b.stereo.size());
  for (std::size_t i = 0; i < a.stereo.size(); ++i) {
    EXPECT_EQ(a.stereo[i].rig_id, b.stereo[i].rig_id);
    for (auto side : {&StereoFrame::left, &StereoFrame::right}) {
      const CameraFrame& ca = a.stereo[i].*side;
      const CameraFrame& cb = b.stereo[i].*side;
      EXPECT_EQ(ca.stamp_ns, cb.stamp_ns);
      EXPECT_EQ(ca.sequence, cb.sequence);
      EXPECT_EQ(ca.camera_id, cb.camera_id);
      ExpectSameImage(ca.image, cb.image);
    }
  }
  ASSERT_EQ(a.rgbd.has_value(), b.rgbd.has_value());
  if (a.rgbd) {
    ExpectSameImage(a.rgbd->rgb, b.rgbd->rgb);
    ExpectSameImage(a.rgbd->depth, b.rgbd->depth);
    EXPECT_EQ(a.rgbd->depth_scale_m, b.rgbd->depth_scale_m);
    EXPECT_EQ(a.rgbd->stamp_ns, b.rgbd->stamp_ns);
  }
  ASSERT_EQ(a.vehicle.has_value(), b.vehicle.has_value());
  if (a.vehicle) {
    EXPECT_NEAR((a.vehicle->T_world_vehicle.matrix() - b.vehicle->T_world_vehicle.matrix()).norm(),
                0.0, kPoseTolerance);
    EXPECT_EQ(a.vehicle->speed_mps, b.vehicle->speed_mps);
    EXPECT_EQ(a.vehicle->yaw_rate_radps, b.vehicle->yaw_rate_radps);
  }
  ASSERT_EQ(a.gnss.has_value(), b.gnss.has_value());
  if (a.gnss) {
    EXPECT_EQ(a.gnss->latitude_deg, b.gnss->latitude_deg);
    EXPECT_EQ(a.gnss->valid, b.gnss->valid);
    EXPECT_EQ(a.gnss->stamp_ns, b.gnss->stamp_ns);
  }
}

// Writes @p count frame sets with the sample calibration; returns them.
std::vector<FrameSet> WriteLog(const std::string& path, int count, ImageEncoding encoding,
                               std::vector<std::uint64_t>* bytes_after_set = nullptr) {
  std::mt19937 rng(42);
  std::vector<FrameSet> sets;
  LogWriter writer(path, encoding);
  writer.WriteCalibration(Calibration::Load(SampleCalibrationPath()), kStartNs);
  for (int k = 0; k < count; ++k) {
    sets.push_back(MakeFrameSet(static_cast<std::uint64_t>(k), &rng));
    writer.Write(sets.back());
    if (bytes_after_set != nullptr) bytes_after_set->push_back(writer.bytes_written());
  }
  writer.Close();
  return sets;
}

std::vector<FrameSet> ReadAll(LogReader* reader) {
  std::vector<FrameSet> sets;
  while (auto set = reader->Next()) sets.push_back(std::move(*set));
  return sets;
}

TEST(LogReaderTest, RawRoundTripReassemblesEveryFrameSet) {
  test::ScratchDir dir;
  const auto written = WriteLog(dir / "run.lcmlog", 5, ImageEncoding::kRaw);
  LogReader reader(dir / "run.lcmlog");
  ASSERT_NE(reader.calibration(), nullptr);
  EXPECT_EQ(reader.calibration()->rigs.size(), 6u);
  EXPECT_EQ(reader.calibration()->rig(3).name, "rear");
  const auto read = ReadAll(&reader);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) ExpectSameFrameSet(written[i], read[i]);
  EXPECT_FALSE(reader.truncated());
  EXPECT_EQ(reader.truncation_offset(), -1);
  EXPECT_EQ(reader.status().cameras.at(0).completed, 5u);
  EXPECT_EQ(reader.status().cameras.at(0).dropped, 0u);
}

TEST(LogReaderTest, PngRoundTripIsLossless) {
  test::ScratchDir dir;
  const auto written = WriteLog(dir / "png.lcmlog", 3, ImageEncoding::kPng);
  LogReader reader(dir / "png.lcmlog");
  const auto read = ReadAll(&reader);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) ExpectSameFrameSet(written[i], read[i]);
}

TEST(LogReaderTest, OtherChannelsPassThroughWithTheirFrameSet) {
  test::ScratchDir dir;
  std::mt19937 rng(7);
  {
    LogWriter writer(dir / "gt.lcmlog");
    const std::string payload = "ground truth 0";
    writer.Write(MakeFrameSet(0, &rng));
    writer.WriteRaw("ROMO_GROUND_TRUTH", kStartNs + 50, payload.data(), payload.size());
    writer.Write(MakeFrameSet(1, &rng));
  }
  LogReader reader(dir / "gt.lcmlog");
  EXPECT_EQ(reader.calibration(), nullptr);  // none was written
  // Events written after a set (its ground truth, its outputs) come with that set.
  ASSERT_TRUE(reader.Next());
  ASSERT_EQ(reader.other_events().size(), 1u);
  EXPECT_EQ(reader.other_events()[0].channel, "ROMO_GROUND_TRUTH");
  EXPECT_EQ(std::string(reader.other_events()[0].data.begin(), reader.other_events()[0].data.end()),
            "ground truth 0");
  EXPECT_EQ(reader.other_events()[0].timestamp_us, (kStartNs + 50) / 1000);
  ASSERT_TRUE(reader.Next());
  EXPECT_TRUE(reader.other_events().empty());
  EXPECT_FALSE(reader.Next());
}

TEST(LogReaderTest, SeekJumpsToTheFirstSetAtOrAfterTheOffset) {
  test::ScratchDir dir;
  WriteLog(dir / "run.lcmlog", 6, ImageEncoding::kRaw);
  LogReader reader(dir / "run.lcmlog");
  // The calibration event is stamped like set 0, so offsets count from set 0.
  reader.Seek(0.25);
  auto set = reader.Next();
  ASSERT_TRUE(set);
  EXPECT_EQ(set->sequence, 3u);
  reader.Seek(0.0);
  EXPECT_EQ(reader.Next()->sequence, 0u);
  reader.Seek(100.0);
  EXPECT_FALSE(reader.Next());

  auto source = OpenSource("log://" + (dir / "run.lcmlog") + "?seek_s=0.4");
  EXPECT_EQ(source->Next()->sequence, 4u);
}

TEST(LogReaderTest, LoopStartsAgainAtTheEnd) {
  test::ScratchDir dir;
  WriteLog(dir / "run.lcmlog", 3, ImageEncoding::kRaw);
  auto source = OpenSource("log://" + (dir / "run.lcmlog") + "?loop=1");
  std::vector<std::uint64_t> sequences;
  for (int i = 0; i < 7; ++i) sequences.push_back(source->Next()->sequence);
  EXPECT_EQ(sequences, (std::vector<std::uint64_t>{0, 1, 2, 0, 1, 2, 0}));
}

TEST(LogReaderTest, RealTimePacingTakesAtLeastTheRecordedSpan) {
  test::ScratchDir dir;
  WriteLog(dir / "run.lcmlog", 4, ImageEncoding::kRaw);  // sets 100 ms apart: 300 ms span
  auto source = OpenSource("log://" + (dir / "run.lcmlog") + "?pacing=realtime");
  const auto start = std::chrono::steady_clock::now();
  int count = 0;
  while (source->Next()) ++count;
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(count, 4);
  // Lower bound only: sleeping never ends early; 1 ms covers clock granularity.
  constexpr double kClockSlackS = 0.001;
  EXPECT_GE(elapsed_s, 0.3 - kClockSlackS);
}

TEST(LogReaderTest, TruncatedLogYieldsEveryCompleteEventAndWhereItWasCut) {
  test::ScratchDir dir;
  std::vector<std::uint64_t> bytes_after;
  const auto written = WriteLog(dir / "run.lcmlog", 4, ImageEncoding::kRaw, &bytes_after);
  // Cut 100 bytes into the first event (rig 0) of the last set.
  const std::int64_t cut_at = static_cast<std::int64_t>(bytes_after[2]);
  ASSERT_EQ(::truncate((dir / "run.lcmlog").c_str(), cut_at + 100), 0);

  LogReader reader(dir / "run.lcmlog");
  const auto read = ReadAll(&reader);
  ASSERT_EQ(read.size(), 3u);
  for (std::size_t i = 0; i < read.size(); ++i) ExpectSameFrameSet(written[i], read[i]);
  EXPECT_TRUE(reader.truncated());
  EXPECT_EQ(reader.truncation_offset(), cut_at);
  ASSERT_FALSE(reader.status().events.empty());
  EXPECT_NE(reader.status().events[0].find("truncated at byte " + std::to_string(cut_at)),
            std::string::npos);

  std::int64_t truncated_at = 0;
  const auto events = ReadAllEvents(dir / "run.lcmlog", &truncated_at);
  EXPECT_EQ(truncated_at, cut_at);
  EXPECT_EQ(events.size(), 1u + 3u * 5u);  // calibration + 3 sets of 5 parts
}

TEST(LogReaderTest, CorruptEventStopsReadingThere) {
  test::ScratchDir dir;
  std::vector<std::uint64_t> bytes_after;
  WriteLog(dir / "run.lcmlog", 3, ImageEncoding::kRaw, &bytes_after);
  {
    std::fstream f(dir / "run.lcmlog", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(bytes_after[1]));
    f.write("XXXX", 4);  // destroys the sync word of set 2's first event
  }
  LogReader reader(dir / "run.lcmlog");
  EXPECT_EQ(ReadAll(&reader).size(), 2u);
  EXPECT_TRUE(reader.truncated());
  EXPECT_EQ(reader.truncation_offset(), static_cast<std::int64_t>(bytes_after[1]));
}

TEST(LogReaderTest, EventTimePastYear2262IsDamageNotATime) {
  test::ScratchDir dir;
  std::vector<std::uint64_t> bytes_after;
  WriteLog(dir / "run.lcmlog", 3, ImageEncoding::kRaw, &bytes_after);
  {
    // 0x0A00... us overflows int64 nanoseconds; the header's time field starts at byte 12.
    std::fstream f(dir / "run.lcmlog", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(bytes_after[1] + 12));
    const char huge_time[8] = {0x0A, 0, 0, 0, 0, 0, 0, 0};
    f.write(huge_time, sizeof huge_time);
  }
  LogReader reader(dir / "run.lcmlog");
  EXPECT_EQ(ReadAll(&reader).size(), 2u);
  EXPECT_EQ(reader.truncation_offset(), static_cast<std::int64_t>(bytes_after[1]));
  ASSERT_FALSE(reader.status().events.empty());
  EXPECT_NE(reader.status().events[0].find("corrupt at byte " + std::to_string(bytes_after[1]) +
                                           " (event time outside 1970..2262)"),
            std::string::npos)
      << reader.status().events[0];
}

TEST(LogReaderTest, GarbageMissingAndEmptyFiles) {
  test::ScratchDir dir;
  std::string garbage(4096, '\0');
  std::mt19937 rng(3);
  for (auto& c : garbage) c = static_cast<char>(rng());
  test::WriteFile(dir / "garbage.lcmlog", garbage);
  EXPECT_EQ(ErrorOf([&] { LogReader reader(dir / "garbage.lcmlog"); }),
            dir / "garbage.lcmlog" +
                ": not an LCM log file (no event sync word 0xEDA1DA01 at byte 0)");
  std::int64_t truncated_at = 0;
  EXPECT_THROW(ReadAllEvents(dir / "garbage.lcmlog", &truncated_at), romo::Error);

  EXPECT_EQ(ErrorOf([&] { LogReader reader(dir / "none.lcmlog"); }),
            dir / "none.lcmlog" + ": recording not found");

  test::WriteFile(dir / "empty.lcmlog", "");
  LogReader empty(dir / "empty.lcmlog");
  EXPECT_FALSE(empty.Next());
  EXPECT_FALSE(empty.truncated());
}

TEST(LogReaderTest, GarbledCalibrationInTheLogIsNamed) {
  test::ScratchDir dir;
  Calibration cal = Calibration::Load(SampleCalibrationPath());
  cal.rigs[1].T.setZero();
  {
    // A well-formed calibration_t message whose YAML has a zero baseline.
    romo_lcm::calibration_t msg;
    msg.stamp_ns = kStartNs;
    msg.yaml = cal.ToYaml();
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    LogWriter writer(dir / "bad.lcmlog");
    writer.WriteRaw(kCalibrationChannel, kStartNs, bytes.data(), bytes.size());
  }
  const std::string message = ErrorOf([&] { LogReader reader(dir / "bad.lcmlog"); });
  EXPECT_NE(message.find(dir / "bad.lcmlog" + ": ROMO_CALIBRATION: rigs[1].T: baseline"),
            std::string::npos)
      << message;
}

TEST(LogReaderTest, BadLogUriOptionsAreRejected) {
  test::ScratchDir dir;
  WriteLog(dir / "run.lcmlog", 1, ImageEncoding::kRaw);
  const std::string base = "log://" + (dir / "run.lcmlog");
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?speed=2"); }).find("unknown option 'speed'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?pacing=slow"); }).find("pacing = 'slow'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?loop=maybe"); }).find("loop = 'maybe'"),
            std::string::npos);
  EXPECT_THROW(OpenSource(base + "?seek_s=-1"), romo::Error);
  // Offsets no microsecond count holds were cast unchecked (undefined; in practice the whole
  // recording from its start); an offset past the last frame delivered nothing, like an empty log.
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?seek_s=inf"); }).find("not a finite number"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?seek_s=1e300"); }).find("'seek_s=1e300' is outside"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenSource(base + "?seek_s=5"); }).find("seek_s = 5 s is past the recording's last frame"),
            std::string::npos);
  EXPECT_TRUE(OpenSource(base + "?seek_s=0")->Next());
}

}  // namespace
}  // namespace romo::drivers
