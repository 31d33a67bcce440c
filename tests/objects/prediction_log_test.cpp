// Prediction logs: every pedestrian track's observed position and predicted path in the vehicle
// frame, local ENU and WGS84, as CSV and as romo_lcm.pedestrian_predictions_t.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/prediction_log.hpp"
#include "test_support.hpp"

namespace romo::objects {
namespace {

constexpr double kMillimetre = 1e-3;  // position agreement across frames and codecs

struct Fixture {
  Atlas atlas = Atlas::Load(test::SourcePath("config/atlas.yaml"));
  LocalEnu enu{Wgs84{48.0833, 11.2833, 600.0}};
  PredictionFrames frames;
  std::vector<Track> tracks;

  Fixture() {
    // Vehicle 30 m east, 40 m north of the origin, facing north-east.
    frames.T_enu_vehicle.translation() = Eigen::Vector3d(30.0, 40.0, 0.0);
    frames.T_enu_vehicle.linear() =
        Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Tracker tracker(atlas, TrackerParams{});
    const double ped_h = 1.75;
    for (int k = 0; k < 15; ++k) {
      Detection ped;
      ped.xy_m = Eigen::Vector2d(5.0 + 0.12 * k, 2.0);  // 1.2 m/s along vehicle x
      ped.length_m = 0.6;
      ped.width_m = 0.4;
      ped.height_m = ped_h;
      ped.classification = atlas.Classify(0.6, 0.4, ped_h);
      Detection car;
      car.xy_m = Eigen::Vector2d(-6.0, -3.0);
      car.length_m = 4.4;
      car.width_m = 1.8;
      car.height_m = 1.5;
      car.classification = atlas.Classify(4.4, 1.8, 1.5);
      tracks = tracker.Update(0.1 * k, {ped, car});
    }
  }
};

TEST(PredictionLogTest, OnlyPedestriansWithPathsInAllFrames) {
  Fixture f;
  ASSERT_EQ(f.tracks.size(), 2u);
  const auto preds = MakePedestrianPredictions(f.tracks, f.atlas, 2'000'000'000, 500'000'000,
                                               f.frames, f.enu, PredictorKind::kRls);
  ASSERT_EQ(preds.size(), 1u) << "the car has no path prediction";
  const PedestrianPrediction& p = preds[0];
  EXPECT_EQ(p.observed_stamp_ns, 500'000'000 + 1'400'000'000);
  EXPECT_NEAR(p.observed.dt_s, -0.1, 1e-9);
  ASSERT_EQ(p.path.size(), 48u);
  EXPECT_LT((p.observed.vehicle_xy_m - Eigen::Vector2d(6.68, 2.0)).norm(), kMillimetre);
  for (const LoggedPoint& q : p.path) {
    // ENU from the vehicle pose, WGS84 from ENU, and back.
    const Eigen::Vector3d enu = f.frames.T_enu_vehicle * Eigen::Vector3d(q.vehicle_xy_m.x(), q.vehicle_xy_m.y(), 0.0);
    EXPECT_LT((enu - q.enu_m).norm(), kMillimetre);
    EXPECT_LT((f.enu.ToEnu(q.wgs84) - q.enu_m).norm(), kMillimetre);
    // A rotation keeps the covariance's size.
    EXPECT_NEAR(q.enu_cov_m2.trace(), q.vehicle_cov_m2.trace(), 1e-12);
  }
  // Walking along vehicle x = north-east in ENU at 1.2 m/s.
  EXPECT_NEAR(p.velocity_enu_mps.x(), 1.2 / std::sqrt(2.0), 0.05);
  EXPECT_NEAR(p.velocity_enu_mps.y(), 1.2 / std::sqrt(2.0), 0.05);
}

TEST(PredictionLogTest, CsvHasHeaderAndOneRowPerPosition) {
  Fixture f;
  test::ScratchDir dir;
  const std::string path = dir / "predictions.csv";
  const auto preds = MakePedestrianPredictions(f.tracks, f.atlas, 2'000'000'000, 0, f.frames,
                                               f.enu, PredictorKind::kRls);
  {
    PredictionCsvWriter writer(path);
    writer.WriteFrame(preds);
    writer.WriteFrame(preds);
    EXPECT_EQ(writer.rows_written(), 2 * 49);
    EXPECT_TRUE(std::ifstream(path + ".partial").good()) << "in progress under .partial";
  }
  std::istringstream in(test::ReadFile(path));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, PredictionCsvHeader());
  int rows = 0;
  std::string first;
  while (std::getline(in, line)) {
    if (rows == 1) first = line;
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 21) << line;
  }
  EXPECT_EQ(rows, 2 * 49);
  EXPECT_EQ(first.rfind("2000000000,", 0), 0u) << first;
  EXPECT_NE(first.find(",confirmed,0,"), std::string::npos) << first;
  EXPECT_THROW(PredictionCsvWriter("/nonexistent/dir/p.csv"), romo::Error);

  // A .partial left by a killed writer is moved aside, not truncated by the next run.
  { std::ofstream(path + ".partial") << "killed mid-run\n"; }
  PredictionCsvWriter next(path);
  EXPECT_EQ(next.kept_interrupted(), dir / "predictions.interrupted-1.csv");
  EXPECT_EQ(test::ReadFile(dir / "predictions.interrupted-1.csv"), "killed mid-run\n");
}

TEST(PredictionLogTest, LcmRoundTripKeepsEveryField) {
  Fixture f;
  const auto preds = MakePedestrianPredictions(f.tracks, f.atlas, 2'000'000'000, 0, f.frames,
                                               f.enu, PredictorKind::kConstantVelocity);
  const auto bytes = EncodePedestrianPredictions(2'000'000'000, 20, preds);
  std::int64_t sequence = 0;
  const auto back = DecodePedestrianPredictions(bytes.data(), bytes.size(), &sequence);
  EXPECT_EQ(sequence, 20);
  ASSERT_EQ(back.size(), preds.size());
  EXPECT_EQ(back[0].track_id, preds[0].track_id);
  EXPECT_EQ(back[0].state, preds[0].state);
  EXPECT_EQ(back[0].predictor, PredictorKind::kConstantVelocity);
  ASSERT_EQ(back[0].path.size(), preds[0].path.size());
  for (std::size_t k = 0; k < back[0].path.size(); ++k) {
    EXPECT_DOUBLE_EQ(back[0].path[k].wgs84.latitude_deg, preds[0].path[k].wgs84.latitude_deg);
    EXPECT_TRUE(back[0].path[k].enu_cov_m2.isApprox(preds[0].path[k].enu_cov_m2));
  }
  // Truncated or foreign bytes are an error, not a crash.
  EXPECT_THROW(DecodePedestrianPredictions(bytes.data(), bytes.size() / 2), romo::Error);
  const std::vector<std::uint8_t> junk(64, 0xAB);
  EXPECT_THROW(DecodePedestrianPredictions(junk.data(), junk.size()), romo::Error);
}

TEST(PredictionLogTest, CorruptCountIsRejectedBeforeAllocating) {
  // An empty frame ends with num_predictions = 0; 2^31 - 1 of them would make LCM's decoder
  // allocate ~400 GB for a 28-byte message, -1 would make it throw std::length_error.
  std::vector<std::uint8_t> bytes = EncodePedestrianPredictions(1, 2, {});
  ASSERT_EQ(bytes.size(), 28u);
  bytes[24] = 0x7f;
  bytes[25] = bytes[26] = bytes[27] = 0xff;
  try {
    DecodePedestrianPredictions(bytes.data(), bytes.size());
    FAIL() << "a corrupt count was accepted";
  } catch (const romo::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "romo_lcm.pedestrian_predictions_t.num_predictions = 2147483647 does not fit a 28-byte message");
  }
  bytes[24] = 0xff;
  EXPECT_THROW(DecodePedestrianPredictions(bytes.data(), bytes.size()), romo::Error);
}

}  // namespace
}  // namespace romo::objects
