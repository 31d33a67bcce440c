// The run summary (summary.json) counts every track and every pedestrian track once, however
// long the run, from the tracks listed frame by frame.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "romo/pipeline/outputs.hpp"
#include "romo/sim/sim_source.hpp"
#include "test_support.hpp"

namespace {

romo::pipeline::FrameResult FrameWith(std::int64_t sequence, const std::vector<int>& track_ids,
                                      const std::vector<int>& predicted_ids) {
  romo::pipeline::FrameResult f;
  f.frame_sequence = sequence;
  f.stamp_ns = 1'000'000'000 + sequence * 100'000'000;
  for (int id : track_ids) {
    romo::objects::Track t;
    t.id = id;
    f.tracks.push_back(t);
  }
  for (int id : predicted_ids) {
    romo::objects::PedestrianPrediction p;
    p.track_id = id;
    f.predictions.push_back(p);
  }
  return f;
}

// The number after "key": in @p json.
long long Count(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no " << key << " in:\n" << json;
    return -1;
  }
  return std::stoll(json.substr(at + key.size() + 4));
}

std::string SummaryOf(const std::vector<romo::pipeline::FrameResult>& frames) {
  romo::test::ScratchDir dir;
  romo::pipeline::OutputOptions options;
  options.out_dir = dir.path();
  options.frame_pictures = false;
  {
    romo::pipeline::OutputSink sink(romo::sim::SimCalibration(romo::sim::SimParams{}), options);
    for (const auto& f : frames) sink.Write(nullptr, f, {});
    sink.Finish();
  }
  return romo::test::ReadFile(dir / "summary.json");
}

TEST(OutputSummaryTest, TracksAndPedestrianTracksAreCountedOnce) {
  // Track 2 is predicted as a pedestrian, not in frame 1, and again: one pedestrian track.
  const std::string json = SummaryOf({FrameWith(0, {1, 2}, {2}), FrameWith(1, {2, 3}, {}),
                                      FrameWith(2, {2, 3, 4}, {2, 4}), FrameWith(3, {4}, {4})});
  EXPECT_EQ(Count(json, "tracks_total"), 4) << json;
  EXPECT_EQ(Count(json, "pedestrian_tracks"), 2) << json;
  EXPECT_EQ(Count(json, "frames"), 4) << json;
}

TEST(OutputSummaryTest, ALongRunOfShortLivedTracksCountsEachOne) {
  // Each track lives 3 frames, a new one starting every frame, every third one a pedestrian: what
  // a run of hours gives, in which only the tracks alive now are held for the count.
  constexpr int kFrames = 3000;
  std::vector<romo::pipeline::FrameResult> frames;
  for (int k = 0; k < kFrames; ++k) {
    std::vector<int> alive, predicted;
    for (int id = std::max(1, k - 1); id <= k + 1; ++id) {
      alive.push_back(id);
      if (id % 3 == 0) predicted.push_back(id);
    }
    frames.push_back(FrameWith(k, alive, predicted));
  }
  const std::string json = SummaryOf(frames);
  EXPECT_EQ(Count(json, "tracks_total"), kFrames) << json;  // ids 1..kFrames
  EXPECT_EQ(Count(json, "pedestrian_tracks"), kFrames / 3) << json;
}

}  // namespace
