// RLS path prediction vs the constant-velocity baseline on real ETH/UCY pedestrian trajectories,
// and the reader's handling of bad files.
#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/trajectory_eval.hpp"
#include "test_support.hpp"

namespace romo::objects {
namespace {

// The published CV figures are rounded to 0.01 m and the windowing conventions of the
// papers differ slightly; 0.03 m is three rounding steps.
constexpr double kCvReferenceToleranceM = 0.03;

TrajectoryEvalResult Evaluate(const std::string& name) {
  const TrajectorySet set = ReadEthUcy(test::SharedData("eth_ucy/" + name + ".txt"));
  EXPECT_EQ(set.skipped_total(), 0) << "the published files are clean";
  return EvaluateTrajectories(set, WindowParams{}, PredictorParams{});
}

TEST(TrajectoryEvalTest, CvReproducesPublishedHotelFigures) {
  ROMO_REQUIRE_SHARED_DATA("eth_ucy/biwi_hotel.txt");
  const auto r = Evaluate("biwi_hotel");
  EXPECT_NEAR(r.cv.ade_m, 0.32, kCvReferenceToleranceM);
  EXPECT_NEAR(r.cv.fde_m, 0.61, kCvReferenceToleranceM);
  EXPECT_DOUBLE_EQ(r.frame_step, 10.0);
  EXPECT_GT(r.windows, 500);
}

TEST(TrajectoryEvalTest, CvReproducesPublishedZara1Figures) {
  ROMO_REQUIRE_SHARED_DATA("eth_ucy/crowds_zara01.txt");
  const auto r = Evaluate("crowds_zara01");
  EXPECT_NEAR(r.cv.ade_m, 0.43, kCvReferenceToleranceM);
  EXPECT_NEAR(r.cv.fde_m, 0.95, kCvReferenceToleranceM);
}

TEST(TrajectoryEvalTest, RlsNoWorseThanCvOnHotelAndZara1) {
  for (const char* name : {"biwi_hotel", "crowds_zara01"}) {
    ROMO_REQUIRE_SHARED_DATA(std::string("eth_ucy/") + name + ".txt");
    const auto r = Evaluate(name);
    EXPECT_LE(r.romo.ade_m, r.cv.ade_m) << name;
    EXPECT_LE(r.romo.fde_m, r.cv.fde_m) << name;
    std::printf("%s: windows %lld RLS %.3f/%.3f CV %.3f/%.3f\n", name,
                static_cast<long long>(r.windows), r.romo.ade_m, r.romo.fde_m, r.cv.ade_m,
                r.cv.fde_m);
  }
}

// A clean straight walk of 25 frames (2 windows of 20 + ... = 6 windows) for pedestrian 1.
std::string CleanWalk(int ped, int frames, double y) {
  std::string text;
  for (int k = 0; k < frames; ++k) {
    text += std::to_string(10 * k) + "\t" + std::to_string(ped) + "\t" + std::to_string(0.5 * k) +
            "\t" + std::to_string(y) + "\n";
  }
  return text;
}

TEST(TrajectoryEvalTest, BadRowsAreSkippedCountedAndReported) {
  test::ScratchDir dir;
  const std::string path = dir / "bad.txt";
  std::string text = CleanWalk(1, 25, 0.0);
  text += "this is not a row\n";             // malformed
  text += "30\t1\t99.0\t99.0\n";            // duplicate frame 30 of pedestrian 1
  text += "40\t2\tnan\t1.0\n";              // NaN
  text += "50\t3\t1.0\t2.0\n";              // pedestrian 3 seen once
  text += "60\t4.5\t1.0\t2.0\n";            // non-integer id
  text += "70\t5\t1.0\n";                   // 3 fields
  text += "80\t3e39\t1.0\t2.0\n";            // id beyond any integer type (fuzz_eth_ucy)
  test::WriteFile(path, text);
  const TrajectorySet set = ReadEthUcy(path);
  EXPECT_EQ(set.skipped_malformed, 4);
  EXPECT_EQ(set.skipped_duplicate, 1);
  EXPECT_EQ(set.skipped_nonfinite, 1);
  EXPECT_EQ(set.pedestrians_seen_once, 1);
  ASSERT_FALSE(set.notes.empty());
  EXPECT_NE(set.notes[0].find(path + ":26"), std::string::npos) << set.notes[0];
  // The duplicate keeps the first row, so the walk is intact: 25 - 20 + 1 windows, and a
  // straight uniform walk is predicted exactly by both.
  const auto r = EvaluateTrajectories(set, WindowParams{}, PredictorParams{});
  EXPECT_EQ(r.windows, 6);
  EXPECT_LT(r.cv.ade_m, 1e-9);
  EXPECT_LT(r.romo.fde_m, 1e-9);
}

TEST(TrajectoryEvalTest, StrictModeAndEmptyFilesFailWithFileLineAndValue) {
  test::ScratchDir dir;
  const std::string path = dir / "bad.txt";
  test::WriteFile(path, CleanWalk(1, 25, 0.0) + "40\t2\tnan\t1.0\n");
  try {
    ReadEthUcy(path, /*strict=*/true);
    ADD_FAILURE() << "strict read accepted a NaN row";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":26"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nan"), std::string::npos) << e.what();
  }
  test::WriteFile(path, "garbage\n");
  EXPECT_THROW(ReadEthUcy(path), romo::Error);
  EXPECT_THROW(ReadEthUcy(dir / "missing.txt"), romo::Error);
  // Too short for one window of 20.
  test::WriteFile(path, CleanWalk(1, 12, 0.0));
  EXPECT_THROW(EvaluateTrajectories(ReadEthUcy(path), WindowParams{}, PredictorParams{}),
               romo::Error);
  // A gap in the frames breaks windows instead of bridging it.
  test::WriteFile(path, CleanWalk(1, 19, 0.0) + "200\t1\t9.5\t0\n");
  EXPECT_THROW(EvaluateTrajectories(ReadEthUcy(path), WindowParams{}, PredictorParams{}),
               romo::Error);
}

}  // namespace
}  // namespace romo::objects
