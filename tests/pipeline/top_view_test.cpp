// Ground truth in the top-view pictures: drawn dashed where the simulator says objects are, and a
// truth message that cannot be read costs the overlay, never the frame's outputs.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "romo/pipeline/outputs.hpp"
#include "romo/sim/ground_truth.hpp"
#include "romo/sim/sim_source.hpp"
#include "romo/viz/top_view.hpp"
#include "test_support.hpp"

namespace {

using romo::viz::TruthOutline;

const cv::Vec3b kBackground(30, 30, 30);

// An empty frame with the ego at the world origin, heading north.
romo::pipeline::FrameResult EmptyFrame() {
  romo::pipeline::FrameResult f;
  f.ego_world.position_m = Eigen::Vector2d::Zero();
  f.ego_world.yaw_rad = 0.0;
  return f;
}

// The pixels along the segment a-b (world metres) that are not the background, as a fraction.
double PaintedFraction(const cv::Mat& img, const romo::viz::TopViewParams& view, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const double px_per_m = view.size_px / view.span_m;
  const int steps = 200;
  int painted = 0;
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector2d w = a + (b - a) * ((k + 0.5) / steps);
    const int col = static_cast<int>(std::lround(view.size_px / 2.0 + w.x() * px_per_m));
    const int row = static_cast<int>(std::lround(view.size_px / 2.0 - w.y() * px_per_m));
    painted += img.at<cv::Vec3b>(row, col) != kBackground;
  }
  return static_cast<double>(painted) / steps;
}

TEST(TopViewTest, TruthIsDrawnDashedWhereItIs) {
  romo::viz::TopViewParams view;
  // Off the 5 m grid lines so that only the outline can paint these pixels.
  const std::vector<Eigen::Vector2d> car = {{5.3, 1.3}, {5.3, 3.7}, {9.7, 3.7}, {9.7, 1.3}};
  const cv::Mat with = romo::viz::DrawTopView(EmptyFrame(), view, {}, "", {TruthOutline{"car", car}});
  const cv::Mat without = romo::viz::DrawTopView(EmptyFrame(), view, {}, "");
  for (std::size_t k = 0; k < car.size(); ++k) {
    const Eigen::Vector2d& a = car[k];
    const Eigen::Vector2d& b = car[(k + 1) % car.size()];
    // Dashes: about half of each side painted (6 px dashes and gaps; anti-aliasing widens each
    // dash by about a pixel at both ends: ~0.65), where a detection's solid box paints all of it.
    const double painted = PaintedFraction(with, view, a, b);
    EXPECT_GT(painted, 0.3) << "side " << k;
    EXPECT_LT(painted, 0.85) << "side " << k;
    EXPECT_EQ(PaintedFraction(without, view, a, b), 0.0) << "side " << k;
  }
  // Nothing drawn inside the outline: it is an outline.
  EXPECT_EQ(PaintedFraction(with, view, {6.0, 2.5}, {9.0, 2.5}), 0.0);
}

// A sink writing one frame with @p truth passed through, as `romo run` and `romo replay` do.
void WriteOneFrame(const std::string& out_dir, const romo::drivers::LogEvent& truth, double span_m = 36.0) {
  romo::pipeline::OutputOptions options;
  options.out_dir = out_dir;
  options.picture_span_m = span_m;
  romo::pipeline::OutputSink sink(romo::sim::SimCalibration(romo::sim::SimParams{}), options);
  sink.Write(nullptr, EmptyFrame(), {truth});
  sink.Finish();
}

romo::drivers::LogEvent TruthOfOnePerson(romo::sim::GtBox* person_out) {
  romo::sim::GroundTruth truth;
  romo::sim::GtBox person;
  person.id = 7;
  person.class_name = "pedestrian";
  person.center_m = {3.6, -6.2, 0.85};
  person.size_m = {0.6, 0.6, 1.7};
  truth.objects.push_back(person);
  *person_out = person;
  romo::drivers::LogEvent e;
  e.channel = romo::sim::kGroundTruthChannel;
  e.data = romo::sim::Encode(truth);
  return e;
}

TEST(TopViewTest, RunPicturesShowThePassedThroughTruth) {
  romo::sim::GtBox person;
  const romo::drivers::LogEvent e = TruthOfOnePerson(&person);
  romo::test::ScratchDir dir;
  WriteOneFrame(dir.path(), e);
  const cv::Mat img = cv::imread(dir / "frames/frame_000000.png");
  ASSERT_FALSE(img.empty());
  const romo::viz::TopViewParams view;
  // The person's near side (x = 3.3 m) is drawn, and the picture equals one drawn directly.
  EXPECT_GT(PaintedFraction(img, view, {3.3, -6.5}, {3.3, -5.9}), 0.3);
  const cv::Mat direct =
      romo::viz::DrawTopView(EmptyFrame(), view, {}, "", {TruthOutline{"pedestrian", person.Footprint()}});
  EXPECT_EQ(cv::norm(img, direct, cv::NORM_INF), 0.0);
}

TEST(TopViewTest, PictureSpanZoomsAboutTheVehicle) {
  romo::sim::GtBox person;
  const romo::drivers::LogEvent e = TruthOfOnePerson(&person);
  romo::test::ScratchDir dir;
  WriteOneFrame(dir.path(), e, 18.0);
  const cv::Mat img = cv::imread(dir / "frames/frame_000000.png");
  ASSERT_FALSE(img.empty());
  romo::viz::TopViewParams zoomed;
  zoomed.span_m = 18.0;
  // Twice the pixels per metre: the near side lies where the 18 m scale puts it, not the 36 m one.
  EXPECT_GT(PaintedFraction(img, zoomed, {3.3, -6.5}, {3.3, -5.9}), 0.3);
  EXPECT_EQ(PaintedFraction(img, romo::viz::TopViewParams{}, {3.3, -6.5}, {3.3, -5.9}), 0.0);
}

TEST(TopViewTest, PictureSpanOutOfRangeIsRefusedByName) {
  for (const char* command : {"run", "replay x.lcmlog", "fuse"}) {
    const auto res = romo::test::RunRomo(std::string(command) + " --picture-span 0.5");
    EXPECT_NE(res.exit_code, 0) << command;
    EXPECT_NE((res.err + res.out).find("--picture-span"), std::string::npos) << command << ": " << res.err;
  }
}

TEST(TopViewTest, UnreadableTruthCostsTheOverlayNotTheFrame) {
  romo::drivers::LogEvent e;
  e.channel = romo::sim::kGroundTruthChannel;
  e.data = {0xde, 0xad, 0xbe, 0xef};
  romo::test::ScratchDir dir;
  WriteOneFrame(dir.path(), e);
  EXPECT_TRUE(std::filesystem::exists(dir / "frames/frame_000000.png"));
  const std::string summary = romo::test::ReadFile(dir / "summary.json");
  EXPECT_NE(summary.find("\"frames\": 1"), std::string::npos) << summary;
  EXPECT_NE(summary.find("pictures drawn without ground truth"), std::string::npos) << summary;
  EXPECT_NE(summary.find("ROMO_GT_FRAME"), std::string::npos) << summary;
}

}  // namespace
