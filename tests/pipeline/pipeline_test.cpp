// The pipeline after stereo on a synthetic 360 deg cloud, and `romo run` end to end (small).
#include "romo/pipeline/pipeline.hpp"

#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "test_support.hpp"

namespace romo::pipeline {
namespace {

// Tolerance on a box centre from a dense, noise-free synthetic car: the voxel leaf (0.15 m)
// bounds how far the footprint can be off.
constexpr double kBoxCentreTolM = 0.15;

// Ground points around the vehicle plus a car-sized block 6 m ahead (vehicle frame).
RigInput SyntheticRig(int rig_id, std::int64_t stamp_ns) {
  RigInput in;
  in.rig_id = rig_id;
  in.stamp_ns = stamp_ns;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-12.f, 12.f);
  for (int i = 0; i < 20000; ++i) in.cloud.PushBack({u(rng), u(rng), 0.f}, 0.01f, 100.f);
  if (rig_id == 0) {
    for (float x = 4.0f; x <= 8.5f; x += 0.05f) {
      for (float y = -0.9f; y <= 0.9f; y += 0.05f) in.cloud.PushBack({x, y, 1.5f}, 0.01f, 50.f);
      for (float z = 0.3f; z <= 1.5f; z += 0.05f) {
        in.cloud.PushBack({x, -0.9f, z}, 0.01f, 50.f);
        in.cloud.PushBack({x, 0.9f, z}, 0.01f, 50.f);
      }
    }
  }
  return in;
}

TEST(PipelineTest, SyntheticCarBoxedClassifiedAndMissingRigReported) {
  const auto calibration = drivers::Calibration::Load(drivers::SampleCalibrationPath());
  Pipeline pipe(calibration, PipelineParams{});
  std::vector<RigInput> rigs;
  for (int k = 0; k < 5; ++k) rigs.push_back(SyntheticRig(k, 1000));  // rig 5 missing
  const FrameResult r = pipe.ProcessClouds(1000, 1, rigs, std::nullopt, std::nullopt);
  ASSERT_EQ(r.missing_rigs, std::vector<int>{5});
  ASSERT_EQ(r.status.rigs.size(), 6u);
  EXPECT_FALSE(r.status.rigs[5].present);
  bool reported = false;
  for (const auto& e : r.status.events) reported |= e.find("rig 5") != std::string::npos;
  EXPECT_TRUE(reported);
  ASSERT_EQ(r.obstacles.obstacles.size(), 1u);
  const auto& car = r.obstacles.obstacles[0];
  EXPECT_EQ(car.class_name, "car");
  EXPECT_NEAR(car.center_m.x(), 6.25, kBoxCentreTolM);
  EXPECT_NEAR(car.center_m.y(), 0.0, kBoxCentreTolM);
  // Every stage was timed.
  EXPECT_GE(r.status.stages.size(), 8u);
}

TEST(PipelineTest, OutOfOrderStampIsAClearError) {
  const auto calibration = drivers::Calibration::Load(drivers::SampleCalibrationPath());
  Pipeline pipe(calibration, PipelineParams{});
  pipe.ProcessClouds(2000, 1, {SyntheticRig(0, 2000)}, std::nullopt, std::nullopt);
  try {
    pipe.ProcessClouds(1000, 2, {SyntheticRig(0, 1000)}, std::nullopt, std::nullopt);
    FAIL() << "no error";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("out-of-order"), std::string::npos) << e.what();
  }
}

TEST(PipelineTest, RunEndToEndWritesOutputsAndEvaluation) {
  romo::test::ScratchDir dir;
  const auto res = romo::test::RunRomo("run --frames 2 --scale 0.25 --no-pictures --out " + dir.path());
  ASSERT_EQ(res.exit_code, 0) << res.err;
  for (const char* f : {"summary.json", "eval.json", "outputs.lcmlog", "predictions.csv", "stage_approach.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  const std::string eval = romo::test::ReadFile(dir / "eval.json");
  for (const char* key : {"\"frames\":2", "\"car\"", "\"pedestrian\"", "\"box_center_err_m_median\"",
                          "\"id_switches\"", "\"prediction\"", "\"slot\"", "\"narrow_reported_feasible\""}) {
    EXPECT_NE(eval.find(key), std::string::npos) << key << " in " << eval;
  }
  const auto json = romo::test::RunRomo("eval scene --json --log " + (dir / "outputs.lcmlog"));
  EXPECT_EQ(json.exit_code, 0) << json.err;
  EXPECT_NE(json.out.find("\"frames\":2"), std::string::npos) << json.out;
  // A recording without calibration is refused with a clear message.
  romo::test::WriteFile(dir / "empty.lcmlog", "");
  const auto bad = romo::test::RunRomo("replay " + (dir / "empty.lcmlog") + " --out " + (dir / "x"));
  EXPECT_NE(bad.exit_code, 0);
}

}  // namespace
}  // namespace romo::pipeline
