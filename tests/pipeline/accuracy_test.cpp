// Accuracy of the whole stack on the simulated parking scene `romo run` uses (40 frames), over
// seeds 1-5 (seed 1 is `romo run`'s default): detection, boxes, tracks and the parking slot against
// the scene's ground truth, scored by `romo eval scene`.
//
// At the rigs' own resolution (`--scale 1`) every target of the issue is met over the five scenes
// pooled, and asserted as the issue states it. At `romo run`'s default half resolution (a quarter of
// the stereo work, twice the depth noise) the slot's targets are asserted in every scene; the
// recall, precision and box-centre targets are not yet met there, so today's five-seed means are
// asserted as floors a little below the figures measured, so that a change that loses accuracy fails
// here instead of passing unnoticed (README "Accuracy"). One seed's figures move by several
// sightings with any change to the stack (which blob a track takes, which view a parked car is
// remembered from); the five scenes together are what a change is judged by. Each run is
// deterministic for a build (fixed seed, rendering and matching independent of thread count).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "romo/pipeline/scene_eval.hpp"
#include "test_support.hpp"

namespace romo::pipeline {
namespace {

constexpr int kSeeds = 5;

double HiddenRecall(const HiddenScore& h) { return h.truths ? double(h.matched_truths) / h.truths : 1.0; }

struct Means {
  double car_p = 0, car_r = 0, ped_p = 0, ped_r = 0, car_visible_r = 0, ped_visible_r = 0;
  double car_hidden_r = 0, ped_hidden_r = 0;  // found among the sightings hidden now
  double centre_m = 0, car_yaw_deg = 0, slot_centre_m = 0;
  long long slot_found = 0, slot_visible = 0;

  void Add(const SceneEval& e) {
    car_p += e.car.precision() / kSeeds;
    car_r += e.car.recall() / kSeeds;
    ped_p += e.pedestrian.precision() / kSeeds;
    ped_r += e.pedestrian.recall() / kSeeds;
    car_visible_r += e.car_visible.recall() / kSeeds;
    ped_visible_r += e.pedestrian_visible.recall() / kSeeds;
    car_hidden_r += HiddenRecall(e.car_hidden) / kSeeds;
    ped_hidden_r += HiddenRecall(e.pedestrian_hidden) / kSeeds;
    centre_m += e.box_center_err_m_median / kSeeds;
    car_yaw_deg += e.car_yaw_err_deg_median / kSeeds;
    slot_centre_m += e.slot_center_err_m / kSeeds;
    slot_found += e.slot_found_frames;
    slot_visible += e.slot_visible_frames;
  }
};

void PrintSceneFigures(const std::string& what, const SceneEval& e) {
  std::printf("FIGURE accuracy %s: car P %.3f R %.3f (%lld/%lld), pedestrian P %.3f R %.3f (%lld/%lld), box "
              "centre %.3f m, car yaw %.1f deg, ID switches %lld, slot %lld/%lld centre %.3f m yaw %.2f deg, "
              "narrow feasible %lld\n",
              what.c_str(), e.car.precision(), e.car.recall(), static_cast<long long>(e.car.matched_truths),
              static_cast<long long>(e.car.truths), e.pedestrian.precision(), e.pedestrian.recall(),
              static_cast<long long>(e.pedestrian.matched_truths), static_cast<long long>(e.pedestrian.truths),
              e.box_center_err_m_median, e.car_yaw_err_deg_median, static_cast<long long>(e.id_switches),
              static_cast<long long>(e.slot_found_frames), static_cast<long long>(e.slot_visible_frames),
              e.slot_center_err_m, e.slot_yaw_err_deg, static_cast<long long>(e.narrow_reported_feasible()));
  std::printf("FIGURE accuracy %s, objects the cameras can see (>= %.0f %% of their facing surface): car P "
              "%.3f R %.3f (%lld/%lld), pedestrian P %.3f R %.3f (%lld/%lld)\n",
              what.c_str(), 100 * SceneEvalParams{}.min_visible_fraction, e.car_visible.precision(), e.car_visible.recall(),
              static_cast<long long>(e.car_visible.matched_truths), static_cast<long long>(e.car_visible.truths),
              e.pedestrian_visible.precision(), e.pedestrian_visible.recall(),
              static_cast<long long>(e.pedestrian_visible.matched_truths),
              static_cast<long long>(e.pedestrian_visible.truths));
  std::printf("FIGURE accuracy %s, objects hidden from the cameras now: car %lld/%lld found (%lld seen earlier), "
              "pedestrian %lld/%lld (%lld seen earlier)\n",
              what.c_str(), static_cast<long long>(e.car_hidden.matched_truths), static_cast<long long>(e.car_hidden.truths),
              static_cast<long long>(e.car_hidden.seen_before), static_cast<long long>(e.pedestrian_hidden.matched_truths),
              static_cast<long long>(e.pedestrian_hidden.truths), static_cast<long long>(e.pedestrian_hidden.seen_before));
  std::printf("FIGURE accuracy %s: box centre median cars %.3f m, pedestrians %.3f m\n", what.c_str(),
              e.car.center_err_m_median, e.pedestrian.center_err_m_median);
}

TEST(AccuracyTest, ParkingScenesMeetTheirTargetsOrTodaysFloors) {
  Means mean;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    romo::test::ScratchDir dir;
    const auto run = romo::test::RunRomo("run --no-pictures --seed " + std::to_string(seed) + " --out " + dir.path());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const SceneEval e = EvaluateSceneLog(dir / "outputs.lcmlog");
    PrintSceneFigures("seed " + std::to_string(seed), e);
    // The median of all matched boxes lies between the two classes' medians.
    EXPECT_GE(e.box_center_err_m_median, std::min(e.car.center_err_m_median, e.pedestrian.center_err_m_median));
    EXPECT_LE(e.box_center_err_m_median, std::max(e.car.center_err_m_median, e.pedestrian.center_err_m_median));
    ASSERT_EQ(e.frames, 40);
    ASSERT_TRUE(e.visibility_scored) << "romo run writes the calibration into its outputs log";
    // Targets met, in every scene.
    EXPECT_LE(e.slot_center_err_m, 0.15);
    EXPECT_LE(e.slot_yaw_err_deg, 3.0);
    EXPECT_EQ(e.narrow_reported_feasible(), 0) << e.MissesText();  // (the frames, with the slot behind each)
    // Hidden objects (about 40 car and 25 pedestrian sightings a scene) are neither missed nor
    // found there: every sighting is scored once, as visible or as hidden. (Visible recall is not
    // bound to exceed the whole's: the memory finds 0.6-0.9 of the hidden cars.)
    EXPECT_LT(e.car_visible.truths, e.car.truths);
    EXPECT_EQ(e.car_visible.truths + e.car_hidden.truths, e.car.truths);
    EXPECT_EQ(e.car_visible.matched_truths + e.car_hidden.matched_truths, e.car.matched_truths);
    EXPECT_EQ(e.pedestrian_visible.truths + e.pedestrian_hidden.truths, e.pedestrian.truths);
    EXPECT_EQ(e.pedestrian_visible.matched_truths + e.pedestrian_hidden.matched_truths,
              e.pedestrian.matched_truths);
    // `--misses` lists exactly the visible truths missed and the detections matched to none.
    std::int64_t missed = 0, false_alarms = 0;
    for (const ClassScore* c : {&e.car_visible, &e.pedestrian_visible}) {
      missed += c->truths - c->matched_truths;
      false_alarms += c->detections - c->matched_detections;
    }
    EXPECT_EQ(static_cast<std::int64_t>(e.misses.size()), missed);
    EXPECT_EQ(static_cast<std::int64_t>(e.false_alarms.size()), false_alarms);
    // ... then the hidden ones the cameras saw before that memory did not carry.
    EXPECT_EQ(static_cast<std::int64_t>(e.hidden_misses.size()),
              e.car_hidden.seen_before - e.car_hidden.seen_before_matched + e.pedestrian_hidden.seen_before -
                  e.pedestrian_hidden.seen_before_matched);
    for (const SceneMiss& m : e.hidden_misses) EXPECT_LT(m.visible_fraction, SceneEvalParams{}.min_visible_fraction);
    // ... and each frame whose fully visible feasible bay was not found.
    EXPECT_EQ(static_cast<std::int64_t>(e.slot_misses.size()), e.slot_visible_frames - e.slot_found_frames);
    for (const SceneSlotMiss& m : e.slot_misses) {
      EXPECT_LE(std::hypot(m.x_m, m.y_m), SceneEvalParams{}.bay_visible_range_m);
      EXPECT_EQ(m.slot_near, !m.slot_reason.empty()) << "a slot near the bay is listed only when infeasible";
    }
    // Every sighting is either visible or hidden now, and found or not in both tallies alike.
    for (const auto& [all, visible, hidden] : {std::tie(e.car, e.car_visible, e.car_hidden),
                                               std::tie(e.pedestrian, e.pedestrian_visible, e.pedestrian_hidden)}) {
      EXPECT_EQ(hidden.truths, all.truths - visible.truths);
      EXPECT_EQ(hidden.matched_truths, all.matched_truths - visible.matched_truths);
      EXPECT_LE(hidden.seen_before_matched, std::min(hidden.seen_before, hidden.matched_truths));
    }
    // In the maneuver almost every object hidden now was seen in an earlier frame (seeds 1-5: all
    // 219 car sightings and 119 of 120 pedestrian ones): what is found of them is the memory's
    // (remembered parked cars, coasting tracks) doing, not out of reach.
    EXPECT_GE(e.car_hidden.seen_before, 0.9 * static_cast<double>(e.car_hidden.truths));
    EXPECT_GE(e.pedestrian_hidden.seen_before, 0.9 * static_cast<double>(e.pedestrian_hidden.truths));
    mean.Add(e);
  }
  std::printf("FIGURE accuracy, mean of seeds 1-%d: car P %.3f R %.3f (visible R %.3f), pedestrian P %.3f R %.3f "
              "(visible R %.3f), box centre %.3f m, car yaw %.1f deg, slot %lld/%lld centre %.3f m\n",
              kSeeds, mean.car_p, mean.car_r, mean.car_visible_r, mean.ped_p, mean.ped_r, mean.ped_visible_r,
              mean.centre_m, mean.car_yaw_deg, mean.slot_found, mean.slot_visible, mean.slot_centre_m);
  std::printf("FIGURE accuracy, mean of seeds 1-%d, objects hidden from the cameras now: car R %.3f, pedestrian R %.3f\n",
              kSeeds, mean.car_hidden_r, mean.ped_hidden_r);
  // Floors: five-seed means measured with stacked pieces merged into people, coasting tracks
  // kept to their class's size and face pairs split at gaps of half density (car P 0.853 R 0.577,
  // visible R 0.642; pedestrian P 0.711 R 0.715, visible R 0.767; centre 0.221 m; car yaw 8.5
  // deg; slot 158/160 at 0.171 m, 160/160 at 0.072 m since its depth is read off the painted line
  // and the kerb, and the neighbours' boxes are smoothed; pedestrian P 0.731 since tracks coasting
  // faster than their class moves are not listed). Before those (session 8): car P 0.836 R 0.585, pedestrian P
  // 0.710 R 0.711, centre 0.225 m, car yaw 9.2 deg; before session 8: car P 0.821 R 0.548,
  // pedestrian P 0.686 R 0.713, centre 0.229 m. Session 12: far cars in a row take the row's
  // heading (PipelineParams::row_align_*): car P 0.853 -> 0.883, R 0.577 -> 0.629 (visible 0.642
  // -> 0.694), pedestrian P 0.731 -> 0.723, R 0.715 -> 0.724, centre 0.221 -> 0.227 m (more far
  // cars matched), car yaw 8.5 -> 6.9 deg; then person-sized pieces inside a hidden remembered
  // parked car left of no class: pedestrian P 0.723 -> 0.765, R 0.724 -> 0.718, car P 0.883 ->
  // 0.878, R 0.629 -> 0.630. Session 13: neighbours beside the vehicle kept in the memory
  // (parked_standing_points_ratio): car P 0.878 -> 0.894, R 0.630 -> 0.635, car yaw 7.0 -> 7.95
  // deg (more near neighbours matched). Session 18: remembered footprints preferred only within
  // 5 m (parked_prefer_max_range_m): car P 0.894 -> 0.900, R 0.635 -> 0.659 (visible 0.701 ->
  // 0.718), pedestrian P 0.766 -> 0.787, R 0.718 -> 0.726, centre 0.225 -> 0.234 m and car yaw
  // 7.95 -> 8.35 deg (more far cars matched, the less exact ones). About 1.5 % (5 of 300
  // sightings a scene) of margin. Session 20: a remembered car is the latest view showing >= 80 %
  // of the most seen of it (parked_keep_view_fraction), not the last sliver before it hides: car P
  // 0.900 -> 0.902, R 0.659 -> 0.668 (visible 0.718 -> 0.724, hidden 0.30 -> 0.33), centre 0.234
  // -> 0.238 m and car yaw 8.4 -> 8.8 deg (more remembered cars matched, boxed less closely).
  // Session 22: the parked-car speed gate grows with the blob's depth noise, and such views never
  // replace a memory from a steady one (parked_speed_per_depth_spread): car P 0.902 -> 0.928, R
  // 0.668 -> 0.735 (visible 0.724 -> 0.778, hidden 0.33 -> 0.47), pedestrians alike, centre 0.238
  // -> 0.244 m and car yaw 8.8 -> 11.1 deg: the far cars now remembered and matched are headed
  // worst (their views 25-50 deg off, README), no box seen before got worse. Session 23: a
  // pedestrian track whose blob is too low for a person (legs hidden) stays a pedestrian
  // (pedestrian_tracks_keep_partial_views), pieces inside a remembered car are no people while a
  // car detection stands in it too: pedestrian P 0.791 -> 0.795, R 0.726 -> 0.751 (visible 0.802);
  // then within 0.5 m around it too, unless a track walked there (parked_pieces_margin_m):
  // pedestrian P 0.795 -> 0.879, R 0.751 -> 0.745 (visible 0.797), hidden cars 0.47 -> 0.50.
  // Session 25: parked cars placed by the paint of their row (PipelineParams::bays_from_paint),
  // ground far below the plane no longer taken for ground, a track that jumped to another car no
  // longer moving its car's memory: car P 0.928 -> 0.913, R 0.735 -> 0.860 (visible 0.774 ->
  // 0.876, hidden 0.505 -> 0.762), pedestrian P 0.879 -> 0.872, R 0.745 -> 0.749, car yaw 10.8
  // -> 1.4 deg, centre 0.245 -> 0.266 m (far cars now found are boxed from their face with the
  // Atlas car's mean length), slot 160/160 -> 159/160. Then pairs matched across the 15 m edge
  // left unscored (the truth on one side, its box on the other): car P 0.913 -> 0.917, R 0.860 ->
  // 0.863, pedestrian P 0.872 -> 0.873, R 0.749 -> 0.759. Session 26: a pedestrian hidden by
  // the one walking beside it follows that companion (TrackerParams::companion_*): pedestrian
  // P 0.873 -> 0.902, R 0.759 -> 0.764, car P 0.917 -> 0.912. Session 27: coasting cars listed
  // where last measured, and not where a car is measured now: car P 0.911 -> 0.939, R 0.863 ->
  // 0.866; then car tracks in a blob of people not listed: car P 0.939 -> 0.945. Session 28:
  // boxes stand on the ground (ground_contact_gap_m) and the Atlas's walkers and riders are 1.5 m
  // tall and up: pedestrian P 0.904 -> 0.889, R 0.764 -> 0.813 (visible 0.819 -> 0.865, hidden
  // 0.39 -> 0.45), car P 0.945 -> 0.950, R 0.866 -> 0.859 (hidden 0.785 -> 0.731: memories half a
  // bay off), centre 0.262 -> 0.274 m (the people now found are the harder ones). Session 30:
  // the far one of two people one behind the other, seen as a sliver beside the near one, is a
  // person too (tandem_far_partly_seen): pedestrian P 0.889 -> 0.890, R 0.813 -> 0.817, centre
  // 0.274 -> 0.270 m (at full resolution, seeds 1-5 with the tracker's standing companions:
  // pedestrians 0.942 / 0.859 -> 0.953 / 0.895). Session 33: a hidden walker's follower glimpsed
  // keeps following (TrackerParams::companion_glimpses), one near another person seen ends:
  // pedestrian P 0.889 -> 0.893, R 0.819 -> 0.829 (hidden 0.48 -> 0.54), car R 0.859 -> 0.862.
  // Session 34 (for full resolution: two car ends joined along the row's front split, a pair side
  // by side in the aisle split, a walker's detection kept from a faster track of another class, a
  // narrow memory tested at the mean car width): car P 0.950 -> 0.958, R 0.862 -> 0.863,
  // pedestrian P 0.893 -> 0.897, R 0.829 -> 0.824 (hidden 0.54 -> 0.52), centre 0.270 -> 0.265 m.
  // Session 35 (a follower's glimpses no longer vote its class, the companion gap 2 m): pedestrian
  // R 0.824 -> 0.827 (hidden 0.52 -> 0.54), centre 0.265 -> 0.266 m.
  EXPECT_GE(mean.car_p, 0.93);
  EXPECT_GE(mean.car_r, 0.84);
  EXPECT_GE(mean.car_visible_r, 0.86);
  EXPECT_GE(mean.ped_p, 0.87);
  EXPECT_GE(mean.ped_r, 0.80);
  EXPECT_GE(mean.ped_visible_r, 0.84);
  EXPECT_LE(mean.centre_m, 0.285);
  EXPECT_LE(mean.car_yaw_deg, 2.5);
  EXPECT_GE(mean.slot_found, mean.slot_visible - 2);
  EXPECT_LE(mean.slot_centre_m, 0.09);
  // Session 19: of the sightings hidden now the memory finds cars 0.30 and pedestrians 0.38 (mean
  // of seeds; seed 3's cars 0.075, seed 5's 0.435): the largest share of recall left (hidden car
  // sightings are 14 % of all, 151 of the 524 car misses of seeds 1-5).
  EXPECT_GE(mean.car_hidden_r, 0.70);  // 0.33 since session 20, 0.47 since 22, 0.76 since 25, 0.73 since 28
  EXPECT_GE(mean.ped_hidden_r, 0.48);  // 0.54 since session 33
}

// The rigs' own resolution (782x582: half the depth noise of the default, four times the stereo
// work), seeds 1-5 pooled, where every target of the issue is met and asserted as it stands: cars
// and pedestrians within 15 m at precision and recall >= 0.95, the box centre within 0.2 m
// (median), the feasible bay found in every frame it is fully visible, its centre within 0.15 m and
// yaw within 3 degrees, the too-narrow bay never reported feasible. Pooled because one scene moves
// by several sightings with any change (seed 4 alone: pedestrian recall 0.927) while
// the issue's figures are about the stack, not one scene. Session 35: cars 0.975 / 0.958,
// pedestrians 0.990 / 0.954 (925 of 970 sightings; 0.986 / 0.951 before a follower's glimpses
// stopped voting its class and the companion gap grew to 2 m), centre 0.192 m, slot 160/160 at
// 0.057 m and 0.65 deg. Before (seed 1 only, floors): car recall 0.665 before parked cars were placed by their
// row's paint, session 25; pedestrians 0.955 / 0.760 before boxes stood on the ground, session 28,
// 0.982 / 0.857 before the far one of a pair in single file was kept from a sliver and a hidden
// walker waited with its companion, session 30; car recall 0.947 before a car's end read as a
// cyclist at the row's front was placed as a car, session 33. The five 40-frame runs take about
// 12 CPU minutes, two at a time.
TEST(AccuracyTest, FullResolutionScenesMeetTheIssuesTargets) {
  std::vector<std::unique_ptr<romo::test::ScratchDir>> dirs;
  for (int i = 0; i < kSeeds; ++i) dirs.push_back(std::make_unique<romo::test::ScratchDir>());
  // Two runs at a time: each keeps about 1.7 of 2 cores busy, so a pair fills the machine.
  std::vector<romo::test::CommandResult> results(kSeeds);
  std::atomic<int> next{0};
  const auto run_seeds = [&] {
    for (int i = next++; i < kSeeds; i = next++) {
      results[static_cast<std::size_t>(i)] = romo::test::RunRomo(
          "run --no-pictures --lcm-url '' --scale 1 --seed " + std::to_string(i + 1) + " --out " +
          dirs[static_cast<std::size_t>(i)]->path());
    }
  };
  auto other = std::async(std::launch::async, run_seeds);
  run_seeds();
  other.get();
  std::vector<std::string> logs;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto& result = results[static_cast<std::size_t>(seed - 1)];
    ASSERT_EQ(result.exit_code, 0) << result.err;
    logs.push_back(*dirs[static_cast<std::size_t>(seed - 1)] / "outputs.lcmlog");
    const SceneEval e = EvaluateSceneLog(logs.back());
    PrintSceneFigures("seed " + std::to_string(seed) + " at full resolution", e);
    ASSERT_EQ(e.frames, 40);
    EXPECT_EQ(e.narrow_reported_feasible(), 0) << e.MissesText();
    EXPECT_EQ(e.slot_found_frames, e.slot_visible_frames) << e.MissesText();
    EXPECT_LE(e.slot_center_err_m, 0.15);
    EXPECT_LE(e.slot_yaw_err_deg, 3.0);
  }
  const SceneEval pooled = EvaluateSceneLogs(logs);
  PrintSceneFigures("seeds 1-5 at full resolution, pooled", pooled);
  ASSERT_EQ(pooled.frames, 40 * kSeeds);
  EXPECT_GE(pooled.car.precision(), 0.95);
  EXPECT_GE(pooled.car.recall(), 0.95);
  EXPECT_GE(pooled.pedestrian.precision(), 0.95);
  EXPECT_GE(pooled.pedestrian.recall(), 0.95);
  EXPECT_LE(pooled.box_center_err_m_median, 0.2);
  EXPECT_EQ(pooled.slot_found_frames, pooled.slot_visible_frames);
  EXPECT_LE(pooled.slot_center_err_m, 0.15);
  EXPECT_LE(pooled.slot_yaw_err_deg, 3.0);
  EXPECT_EQ(pooled.narrow_reported_feasible(), 0);
  // What was missed and what was reported instead, to start from when a target fails.
  if (::testing::Test::HasFailure()) std::printf("%s", pooled.MissesText().c_str());
}

}  // namespace
}  // namespace romo::pipeline
