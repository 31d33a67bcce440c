// Hardware-in-loop: recordings served by `romo gige-serve` as emulated GigE Vision cameras, grabbed
// through gige:// (the real Aravis path), recorded and read back pixel for pixel. Inside netns-run.
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hil_support.hpp"
#include "romo/drivers/gige.hpp"
#include "romo/drivers/recording.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kPeriodNs = 100000000;  // recordings at 10 Hz

// Textured content that differs per frame, rig and side, so every image is identifiable.
Image Textured(PixelFormat format, int width, int height, int frame, int rig, int side) {
  Image image = Image::Allocate(format, width, height);
  const int channels = BytesPerPixel(format) == 3 ? 3 : 1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const unsigned value = (x * 7u + y * 13u + ((x / 8 + y / 8) % 2) * 300u + frame * 101u +
                                rig * 37u + side * 57u + c * 71u) * 2654435761u >> 7;
        if (format == PixelFormat::kMono16) {
          const std::uint16_t sample = value % 4096;  // 12-bit camera values
          std::memcpy(image.row(y) + 2 * x, &sample, 2);
        } else {
          image.row(y)[x * channels + c] = static_cast<std::uint8_t>(value);
        }
      }
    }
  }
  return image;
}

bool Same(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.format != b.format) return false;
  const std::size_t row = static_cast<std::size_t>(a.width) * BytesPerPixel(a.format);
  for (int y = 0; y < a.height; ++y) {
    if (std::memcmp(a.row(y), b.row(y), row) != 0) return false;
  }
  return true;
}

struct Served {
  // frames[rig][k] = {left, right}
  std::vector<std::vector<std::pair<Image, Image>>> frames;
};

Served WriteRecording(const std::string& path, int rigs, int count, int width, int height,
                      const Calibration* calibration) {
  Served served;
  served.frames.resize(rigs);
  LogWriter writer(path);
  if (calibration) writer.WriteCalibration(*calibration, 0);
  for (int k = 0; k < count; ++k) {
    FrameSet set;
    set.stamp_ns = (k + 1) * kPeriodNs;
    set.sequence = k;
    for (int rig = 0; rig < rigs; ++rig) {
      // The RoMo front rig is colour, the others 12-bit mono.
      const PixelFormat format = (rig == 0 && rigs > 1) ? PixelFormat::kRgb8 : PixelFormat::kMono16;
      StereoFrame stereo;
      stereo.rig_id = rig;
      stereo.left.image = Textured(format, width, height, k, rig, 0);
      stereo.right.image = Textured(format, width, height, k, rig, 1);
      stereo.left.stamp_ns = stereo.right.stamp_ns = set.stamp_ns;
      stereo.left.sequence = stereo.right.sequence = k;
      stereo.left.camera_id = "rig" + std::to_string(rig) + "L";
      stereo.right.camera_id = "rig" + std::to_string(rig) + "R";
      served.frames[rig].push_back({stereo.left.image, stereo.right.image});
      set.stereo.push_back(std::move(stereo));
    }
    writer.Write(set);
  }
  writer.Close();
  return served;
}

// Index of the served frame @p image equals, or -1.
int IndexOf(const std::vector<std::pair<Image, Image>>& frames, const Image& image, bool left) {
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (Same(left ? frames[k].first : frames[k].second, image)) return static_cast<int>(k);
  }
  return -1;
}

struct Check {
  int sets = 0;
  int complete_sets = 0;     // every rig present
  int consecutive_steps = 0;  // served index advanced by exactly one between sets
  int steps = 0;
};

// Every recorded image must equal a served one, left and right (and all rigs) the same instant.
Check CheckRecorded(const std::string& path, const Served& served) {
  Check check;
  LogReader reader(path);
  int previous = -1;
  const int count = static_cast<int>(served.frames[0].size());
  while (auto set = reader.Next()) {
    if (set->stereo.empty()) continue;
    ++check.sets;
    int index = -1;
    for (const StereoFrame& stereo : set->stereo) {
      EXPECT_GE(stereo.rig_id, 0);
      EXPECT_LT(stereo.rig_id, static_cast<int>(served.frames.size()));
      const auto& frames = served.frames[stereo.rig_id];
      const int left = IndexOf(frames, stereo.left.image, true);
      const int right = IndexOf(frames, stereo.right.image, false);
      EXPECT_GE(left, 0) << "rig " << stereo.rig_id << " left image of set " << check.sets << " was never served";
      EXPECT_EQ(left, right) << "rig " << stereo.rig_id << " paired images of different instants";
      if (index < 0) index = left;
      EXPECT_EQ(left, index) << "rigs of one frame set show different instants";
      EXPECT_EQ(stereo.left.stamp_ns, stereo.right.stamp_ns);
    }
    if (set->stereo.size() == served.frames.size()) ++check.complete_sets;
    if (previous >= 0) {
      ++check.steps;
      if (index == (previous + 1) % count) ++check.consecutive_steps;
    }
    previous = index;
  }
  return check;
}

// Grabs @p frames sets from gige://@p rig_config into @p out: with `romo record` when the tree has
// it, else through LogWriter in process (same source, same writer).
void Record(const std::string& rig_config, const std::string& out, int frames) {
  if (test::RunRomo("record --help").exit_code == 0) {
    const auto result = test::RunRomo("record --source gige://" + rig_config + " --out " + out +
                                      " --frames " + std::to_string(frames));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    return;
  }
  auto source = OpenSource("gige://" + rig_config);
  LogWriter writer(out);
  if (source->calibration()) writer.WriteCalibration(*source->calibration(), 0);
  for (int i = 0; i < frames; ++i) {
    auto set = source->Next();
    ASSERT_TRUE(set);
    writer.Write(*set);
  }
  writer.Close();
}

TEST(GigeServeHilTest, FullRigServedGrabbedRecordedAndReadBackIdentical) {
  test::ScratchDir dir;
  // The sample calibration's rig 0 is 782x582: the source checks the served size against it.
  Calibration calibration = Calibration::Load(SampleCalibrationPath());
  calibration.rigs = {calibration.rig(0)};
  const Served served = WriteRecording(dir / "served.lcmlog", 1, 8, 782, 582, &calibration);
  hil::Background server(hil::RomoBinary() + " gige-serve --log " + dir / "served.lcmlog" +
                         " --loop --base-address 127.0.0.6 --rig-config-out " + dir / "rig.yaml" +
                         " >" + dir / "serve.out" + " 2>&1");
  ASSERT_TRUE(hil::WaitForFile(dir / "rig.yaml", 20.0)) << test::ReadFile(dir / "serve.out");
  const GigeConfig config = GigeConfig::Load(dir / "rig.yaml");
  ASSERT_EQ(config.rigs.size(), 1u);
  EXPECT_EQ(config.rigs[0].pixel_format, GigePixelFormat::kMono16);
  EXPECT_DOUBLE_EQ(config.rigs[0].frame_rate_hz, 10.0);  // the recording's rate
  EXPECT_FALSE(config.rigs[0].calibration_path.empty());

  constexpr int kFrames = 15;
  Record(dir / "rig.yaml", dir / "grabbed.lcmlog", kFrames);
  const Check check = CheckRecorded(dir / "grabbed.lcmlog", served);
  EXPECT_EQ(check.sets, kFrames);
  EXPECT_EQ(check.complete_sets, kFrames);
  // A consumer starved of CPU (2 shared cores under load ~15) loses frames at the queue, counted
  // as dropped; half the steps must still be exactly one served frame on.
  EXPECT_GE(check.consecutive_steps, check.steps / 2) << check.consecutive_steps << "/" << check.steps;
  EXPECT_TRUE(server.running()) << test::ReadFile(dir / "serve.out");
}

TEST(GigeServeHilTest, TwelveCamerasOfSixRigsDeliverSynchronisedSets) {
  test::ScratchDir dir;
  // Smaller frames than the vehicle's keep the 12-camera run light on a shared machine; the
  // benchmark (`romo bench gige`) runs the full 782x582 size.
  const Served served = WriteRecording(dir / "served.lcmlog", 6, 6, 320, 240, nullptr);
  hil::Background server(hil::RomoBinary() + " gige-serve --log " + dir / "served.lcmlog" +
                         " --loop --base-address 127.0.0.2 --rig-config-out " + dir / "rigs.yaml" +
                         " >" + dir / "serve.out" + " 2>&1");
  ASSERT_TRUE(hil::WaitForFile(dir / "rigs.yaml", 20.0)) << test::ReadFile(dir / "serve.out");
  const GigeConfig config = GigeConfig::Load(dir / "rigs.yaml");
  ASSERT_EQ(config.rigs.size(), 6u);
  EXPECT_EQ(config.rigs[0].pixel_format, GigePixelFormat::kRgb8);

  constexpr int kFrames = 20;
  GigeCameraDiagnostics worst;
  {
    auto source = OpenSource("gige://" + dir / "rigs.yaml");
    // The first sets may miss rigs whose cameras were still being configured when the first
    // ones started; the run is judged after that start-up transient.
    constexpr int kWarmupSets = 5;
    for (int i = 0; i < kWarmupSets; ++i) ASSERT_TRUE(source->Next());
    LogWriter writer(dir / "grabbed.lcmlog");
    for (int i = 0; i < kFrames; ++i) {
      auto set = source->Next();
      ASSERT_TRUE(set);
      std::printf("set %d stamp %lld rigs:", i, static_cast<long long>(set->stamp_ns));
      for (const auto& stereo : set->stereo) {
        std::printf(" %d@%+lldms", stereo.rig_id, static_cast<long long>((stereo.stamp_ns() - set->stamp_ns) / 1000000));
      }
      std::printf("\n");
      writer.Write(*set);
    }
    writer.Close();
    const SourceStatus status = source->status();
    ASSERT_EQ(status.cameras.size(), 12u);
    for (const auto& camera : status.cameras) {
      EXPECT_GT(camera.completed, 0u) << camera.camera_id;
      EXPECT_EQ(camera.incomplete, 0u) << camera.camera_id;  // loopback loses nothing
    }
  }
  const Check check = CheckRecorded(dir / "grabbed.lcmlog", served);
  EXPECT_EQ(check.sets, kFrames);
  // Sets missing a rig happen when a grab thread is starved of CPU (12 cameras on 2 shared cores,
  // load ~15 while other modules build: 6 to 18 of 20 complete seen); half must be complete.
  EXPECT_GE(check.complete_sets, kFrames / 2);
  EXPECT_GE(check.consecutive_steps, check.steps / 2) << check.consecutive_steps << "/" << check.steps;
}

}  // namespace
}  // namespace romo::drivers
