// The CI soak: `romo soak` replays a simulated recording in a loop for 2 minutes and fits
// resident memory, the heap in use and per-frame latency over time; all must stay flat. The
// 30-minute run is the same command with --duration 1800 (README, Reliability).
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace romo {
namespace {

// The number after "key": in soak.json's text.
double JsonNumber(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  if (at == std::string::npos) {
    ADD_FAILURE() << "soak.json has no " << key << ":\n" << json;
    return 0.0;
  }
  return std::stod(json.substr(at + key.size() + 3));
}

// The heap in use's slope through the loop floors (soak.json heap_mb).
double HeapFloorSlope(const std::string& json) {
  const std::size_t heap_at = json.find("\"heap_mb\"");
  if (heap_at == std::string::npos) {
    ADD_FAILURE() << "soak.json has no heap_mb:\n" << json;
    return 0.0;
  }
  return JsonNumber(json.substr(heap_at), "floor_slope_mb_per_min");
}

TEST(SoakTest, TwoMinuteLoopedReplayKeepsMemoryAndLatencyFlat) {
  test::ScratchDir dir;
  // Half resolution: more frames per minute on shared cores, so the fits rest on more samples.
  const auto sim = test::RunRomo("sim --frames 12 --scale 0.5 --out " + dir / "sim.lcmlog");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  constexpr double kDurationS = 120.0, kWarmupS = 20.0;
  const auto soak = test::RunRomo("soak " + dir / "sim.lcmlog" + " --duration " + std::to_string(kDurationS) +
                                  " --warmup " + std::to_string(kWarmupS) + " --out " + dir / "soak");
  ASSERT_EQ(soak.exit_code, 0) << soak.err;
  std::printf("%s", soak.out.c_str());
  const std::string json = test::ReadFile(dir / "soak/soak.json");
  EXPECT_TRUE(std::filesystem::exists(dir / "soak/soak.png"));
  EXPECT_GE(JsonNumber(json, "loops"), 1.0) << "the recording must play more than once";
  // The loop shifts stamps forward: no frame is ever out of order.
  EXPECT_EQ(JsonNumber(json, "skipped_out_of_order"), 0.0);
  EXPECT_GE(JsonNumber(json, "frames_measured"), 30.0);

  // Memory, fitted through each whole loop's lowest sample (what is held between frames), twice.
  // The heap in use (mallinfo2) moves only with what is allocated: +0.03 MB/min here (+0.10-0.15
  // while the run's summary kept every track id ever seen), while a leak of 2 kB per frame at the
  // ~8 frames/s of CI is ~1 MB/min. RSS moves by the allocator's keeping too: loop floors sit on
  // levels ~3 MB apart (~176, ~178, ~179 MB, a whole loop at ~191 now and then), and over 100 s
  // windows of one 5-minute run their fit ranged -3.1 to +3.2 MB/min with no leak; a leak of one
  // half-resolution rig cloud per frame (~25k points x 16 B = 0.4 MB) grows it 24 MB/min even at
  // 1 frame/s.
  constexpr double kMaxHeapSlopeMbPerMin = 1.0, kMaxRssSlopeMbPerMin = 10.0;
  EXPECT_LT(HeapFloorSlope(json), kMaxHeapSlopeMbPerMin) << json;
  EXPECT_LT(JsonNumber(json, "slope_mb_per_min"), kMaxRssSlopeMbPerMin) << json;
  EXPECT_GE(JsonNumber(json, "loops_fitted"), 3.0) << "too few whole loops for the RSS fit:\n" << json;
  // Every loop replays the same frames, so the tracks held per frame must not grow from the
  // first whole loops to the last: one track never pruned per loop adds 1 to the mean per loop
  // (about 50 over the ~60 loops compared here). One loop's mean moves with what the loop before
  // left coasting and remembered: 44.7-48.3 over 63 loops, sd 1.1 (session 20), and single loops
  // once differed by 3.2. The means of 5 loops (sd about 0.5) stay within 3 tracks. Later loops
  // may hold fewer: parked cars remembered from the loop before make the person-sized pieces of
  // their ends no pedestrians (PipelineParams::parked_pieces_unclassified).
  const std::size_t tracks_at = json.find("\"tracks_per_frame\"");
  ASSERT_NE(tracks_at, std::string::npos);
  const std::string tracks = json.substr(tracks_at);
  ASSERT_GE(JsonNumber(tracks, "loops_compared"), 2.0) << "too few whole loops measured:\n" << json;
  EXPECT_GE(JsonNumber(tracks, "loops_averaged"), 1.0) << json;
  EXPECT_LT(JsonNumber(tracks, "last_loops_mean") - JsonNumber(tracks, "first_loops_mean"), 3.0) << json;
  EXPECT_GT(JsonNumber(tracks, "last_loops_mean"), 0.5 * JsonNumber(tracks, "first_loops_mean"))
      << "tracks lost:\n" << json;
  // Time per frame: a structure growing with the frames processed makes every frame cost more, so
  // CPU time per frame and wall latency rise together. This host moves both by itself: loop means
  // of CPU per frame went 334 -> 196 ms within 100 s alone, and another run rose 19 %/min with
  // nothing else running. So the slopes are reported, and only a rise in both above half the mean
  // per minute (per-frame cost doubling in 2 minutes) fails here; the tracks held per loop above
  // are the drift check that host load cannot move.
  const std::size_t cpu_at = json.find("\"cpu_ms_per_frame\"");
  const std::size_t latency_at = json.find("\"latency_ms\"");
  ASSERT_NE(cpu_at, std::string::npos);
  ASSERT_NE(latency_at, std::string::npos);
  const std::string cpu = json.substr(cpu_at), latency = json.substr(latency_at);
  constexpr double kMaxRiseOfMeanPerMin = 0.50;
  const double cpu_rise = JsonNumber(cpu, "slope_ms_per_min") / JsonNumber(cpu, "mean");
  const double latency_rise = JsonNumber(latency, "slope_ms_per_min") / JsonNumber(latency, "mean");
  std::printf("soak: CPU per frame %+.1f %%/min, wall latency %+.1f %%/min\n", 100.0 * cpu_rise, 100.0 * latency_rise);
  EXPECT_FALSE(cpu_rise > kMaxRiseOfMeanPerMin && latency_rise > kMaxRiseOfMeanPerMin)
      << "CPU per frame and wall latency both rise by more than " << 100.0 * kMaxRiseOfMeanPerMin
      << " % of their mean per minute:\n"
      << json;
}

// The memory checks catch a leak: `romo soak --leak-kb-per-frame` keeps that much per frame,
// never freed, and the heap's slope must come out at the leak's rate (frames per minute times
// the leak; malloc adds 16 B a chunk), RSS's well above the bound the test above applies.
TEST(SoakTest, AnInjectedLeakShowsInTheMemorySlopes) {
  test::ScratchDir dir;
  const auto sim = test::RunRomo("sim --frames 12 --scale 0.5 --out " + dir / "sim.lcmlog");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  constexpr double kDurationS = 40.0, kWarmupS = 10.0, kLeakKb = 200.0;
  const auto soak = test::RunRomo("soak " + dir / "sim.lcmlog" + " --duration " + std::to_string(kDurationS) +
                                  " --warmup " + std::to_string(kWarmupS) + " --leak-kb-per-frame " +
                                  std::to_string(kLeakKb) + " --out " + dir / "soak");
  ASSERT_EQ(soak.exit_code, 0) << soak.err;
  const std::string json = test::ReadFile(dir / "soak/soak.json");
  ASSERT_GE(JsonNumber(json, "loops_fitted"), 3.0) << json;
  // Frames per minute over the measured window, from the samples' own count and span.
  const double frames_per_min = JsonNumber(json, "frames_measured") / ((JsonNumber(json, "duration_s") - kWarmupS) / 60.0);
  const double leak_mb_per_min = 1e-3 * kLeakKb * frames_per_min;
  const double heap_slope = HeapFloorSlope(json);
  const double rss_slope = JsonNumber(json, "slope_mb_per_min");
  std::printf("soak with a leak of %.0f kB/frame at %.0f frames/min: %.1f MB/min, heap fitted %.1f, RSS %.1f\n",
              kLeakKb, frames_per_min, leak_mb_per_min, heap_slope, rss_slope);
  // Frames per minute is the mean over the window, the slope the rate at its loops' floors: 10 %.
  EXPECT_NEAR(heap_slope, leak_mb_per_min, 0.1 * leak_mb_per_min) << json;
  EXPECT_GT(rss_slope, 0.5 * leak_mb_per_min) << json;
  EXPECT_GT(rss_slope, 10.0) << json;
}

TEST(SoakTest, BadOptionsAndRecordingsAreRefusedByName) {
  test::ScratchDir dir;
  const std::string out = " --out " + dir / "soak";
  const struct {
    std::string args, named;
  } cases[] = {
      {"x.lcmlog --duration 0", "--duration"},
      {"x.lcmlog --duration 10 --warmup 10", "--warmup"},
      {"x.lcmlog --leak-kb-per-frame -1", "--leak-kb-per-frame"},
      {"x.lcmlog --leak-kb-per-frame nan", "--leak-kb-per-frame"},
      {dir / "missing.lcmlog", "missing.lcmlog"},
  };
  for (const auto& c : cases) {
    const auto res = test::RunRomo("soak " + c.args + out);
    EXPECT_NE(res.exit_code, 0) << c.args;
    EXPECT_NE(res.err.find(c.named), std::string::npos) << c.args << ": " << res.err;
  }
}

}  // namespace
}  // namespace romo
