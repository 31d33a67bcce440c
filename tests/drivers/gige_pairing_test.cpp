// Pairing of left/right frames by device timestamp and frame-id gap counting: pure logic, no network.
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "romo/drivers/gige.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kMs = 1000000;
constexpr std::int64_t kPeriodNs = 100 * kMs;     // 10 Hz
constexpr std::int64_t kToleranceNs = 5 * kMs;    // a real rig's trigger skew is < 1 ms

CameraFrame Stamp(std::int64_t stamp_ns, std::uint64_t sequence = 0) {
  CameraFrame frame;
  frame.stamp_ns = stamp_ns;
  frame.sequence = sequence;
  return frame;
}

TEST(GigePairingTest, DecisionFollowsTolerance) {
  EXPECT_EQ(DecidePair(1000, 1000, 0), PairDecision::kPair);
  EXPECT_EQ(DecidePair(1000, 1000 + kToleranceNs, kToleranceNs), PairDecision::kPair);
  EXPECT_EQ(DecidePair(1000, 1001 + kToleranceNs, kToleranceNs), PairDecision::kLeftUnpaired);
  EXPECT_EQ(DecidePair(1001 + kToleranceNs, 1000, kToleranceNs), PairDecision::kRightUnpaired);
}

TEST(GigePairingTest, JitteredStreamsPairInOrder) {
  StereoPairer pairer(4, kToleranceNs);
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::int64_t> jitter(-2 * kMs, 2 * kMs);  // within tolerance
  constexpr int kFrames = 50;
  for (int i = 0; i < kFrames; ++i) {
    // Arrival order alternates between sides, as two threads would deliver.
    if (i % 2 == 0) {
      pairer.PushLeft(Stamp(i * kPeriodNs + jitter(rng), i));
      pairer.PushRight(Stamp(i * kPeriodNs + jitter(rng), i));
    } else {
      pairer.PushRight(Stamp(i * kPeriodNs + jitter(rng), i));
      pairer.PushLeft(Stamp(i * kPeriodNs + jitter(rng), i));
    }
  }
  for (int i = 0; i < kFrames; ++i) {
    auto pair = pairer.Pop();
    ASSERT_TRUE(pair) << i;
    EXPECT_EQ(pair->rig_id, 4);
    EXPECT_EQ(pair->left.sequence, static_cast<std::uint64_t>(i));
    EXPECT_EQ(pair->right.sequence, static_cast<std::uint64_t>(i));
  }
  EXPECT_FALSE(pairer.Pop());
  EXPECT_EQ(pairer.unpaired_left(), 0u);
  EXPECT_EQ(pairer.unpaired_right(), 0u);
}

TEST(GigePairingTest, LostFramesOnOneSideAreCountedUnpaired) {
  StereoPairer pairer(0, kToleranceNs);
  // Right misses frames 3 and 7; left misses frame 5.
  for (int i = 0; i < 10; ++i) {
    if (i != 5) pairer.PushLeft(Stamp(i * kPeriodNs, i));
    if (i != 3 && i != 7) pairer.PushRight(Stamp(i * kPeriodNs + kMs, i));
  }
  std::vector<std::uint64_t> paired;
  while (auto pair = pairer.Pop()) {
    EXPECT_EQ(pair->left.sequence, pair->right.sequence);
    paired.push_back(pair->left.sequence);
  }
  EXPECT_EQ(paired, (std::vector<std::uint64_t>{0, 1, 2, 4, 6, 8, 9}));
  EXPECT_EQ(pairer.unpaired_left(), 2u);   // 3 and 7
  EXPECT_EQ(pairer.unpaired_right(), 1u);  // 5
}

TEST(GigePairingTest, SkewBeyondToleranceNeverPairs) {
  StereoPairer pairer(0, kToleranceNs);
  for (int i = 0; i < 6; ++i) {
    pairer.PushLeft(Stamp(i * kPeriodNs));
    pairer.PushRight(Stamp(i * kPeriodNs + 3 * kToleranceNs));
  }
  EXPECT_FALSE(pairer.Pop());
  // Each left is older than its right partner by more than the tolerance: all given up; the last
  // right still waits for a later left.
  EXPECT_EQ(pairer.unpaired_left(), 6u);
  EXPECT_EQ(pairer.unpaired_right(), 5u);
}

TEST(GigePairingTest, DeadPartnerBoundsThePendingQueue) {
  constexpr std::size_t kMaxPending = 4;
  StereoPairer pairer(0, kToleranceNs, kMaxPending);
  for (int i = 0; i < 20; ++i) pairer.PushLeft(Stamp(i * kPeriodNs));
  EXPECT_EQ(pairer.unpaired_left(), 20u - kMaxPending);
  // The right camera comes back: the newest pending left still pairs.
  pairer.PushRight(Stamp(19 * kPeriodNs));
  auto pair = pairer.Pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(pair->left.stamp_ns, 19 * kPeriodNs);
  EXPECT_EQ(pairer.unpaired_left(), 20u - 1);
}

TEST(GigePairingTest, ClockRestartFlushesPendingFrames) {
  StereoPairer pairer(0, kToleranceNs);
  pairer.PushLeft(Stamp(50 * kPeriodNs));
  pairer.PushLeft(Stamp(51 * kPeriodNs));
  pairer.PushLeft(Stamp(kPeriodNs));  // the camera was power-cycled: its clock restarted
  EXPECT_EQ(pairer.unpaired_left(), 2u);
  pairer.PushRight(Stamp(kPeriodNs));
  ASSERT_TRUE(pairer.Pop());
}

TEST(GigePairingTest, FrameIdGapHandlesSixteenBitWrap) {
  EXPECT_EQ(FrameIdGap(10, 11), 0u);
  EXPECT_EQ(FrameIdGap(10, 14), 3u);
  EXPECT_EQ(FrameIdGap(65535, 1), 0u);  // 0 is never used by GEV 1.x
  EXPECT_EQ(FrameIdGap(65534, 2), 2u);  // 65535 and 1 lost
  EXPECT_EQ(FrameIdGap(500, 3), 0u);    // counter restarted with the camera
  EXPECT_EQ(FrameIdGap(7, 7), 0u);
  EXPECT_EQ(FrameIdGap(70000, 70010), 9u);  // 64-bit ids (GEV 2) never wrap here
}

}  // namespace
}  // namespace romo::drivers
