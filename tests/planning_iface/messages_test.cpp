// LCM encodings of the planning outputs: round trips, and malformed messages rejected.
#include "romo/planning_iface/messages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <optional>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/planning_iface/lcm_bus.hpp"

namespace romo::planning_iface {
namespace {

constexpr double kExact = 1e-12;         // doubles travel unchanged
constexpr double kFloatTol = 1e-6;       // fields sent as float
constexpr double kQuantumM = 0.0005;     // 1 mm quantisation rounds by at most half a millimetre

ObstacleList SampleObstacles() {
  ObstacleList list;
  list.stamp_ns = 123456789;
  list.frame_sequence = 42;
  for (int i = 0; i < 3; ++i) {
    Obstacle o;
    o.track_id = i + 7;
    o.class_name = i == 0 ? "car" : "pedestrian";
    o.score = 0.5f + 0.1f * i;
    o.center_m = {1.0 + i, -2.0 * i, 0.8};
    o.size_m = {4.5, 1.8, 1.5};
    o.yaw_rad = 0.1 * i;
    o.velocity_mps = {0.3, -0.2};
    o.velocity_cov << 0.01, 0.002, 0.002, 0.02;
    o.num_points = 100 * i;
    list.obstacles.push_back(o);
  }
  return list;
}

ParkingSlotReport SampleSlots() {
  ParkingSlotReport r;
  r.stamp_ns = 99;
  r.frame_sequence = 3;
  r.stage = ManeuverStage::kTurn;
  r.ego_world.position_m = {10.0, 20.0};
  r.ego_world.yaw_rad = 0.7;
  GroundBox a, b;
  a.center_m = {5, 30};
  a.length_m = 4.5;
  a.width_m = 1.8;
  a.id = 1;
  b = a;
  b.center_m = {13.5, 30};
  b.id = 2;
  Pose2 ego = r.ego_world;
  r.slots = FindParkingSlots({a, b}, ego, ParkingParams{});
  r.slots[0].slot_id = 5;
  r.slots[0].confidence = 0.75;
  return r;
}

TEST(MessagesTest, ObstacleListRoundTrip) {
  const ObstacleList in = SampleObstacles();
  const auto bytes = Encode(in);
  std::string why;
  const auto out = DecodeObstacleList(bytes.data(), bytes.size(), &why);
  ASSERT_TRUE(out) << why;
  EXPECT_EQ(out->stamp_ns, in.stamp_ns);
  EXPECT_EQ(out->frame_sequence, in.frame_sequence);
  ASSERT_EQ(out->obstacles.size(), in.obstacles.size());
  for (std::size_t i = 0; i < in.obstacles.size(); ++i) {
    EXPECT_EQ(out->obstacles[i].track_id, in.obstacles[i].track_id);
    EXPECT_EQ(out->obstacles[i].class_name, in.obstacles[i].class_name);
    EXPECT_NEAR((out->obstacles[i].center_m - in.obstacles[i].center_m).norm(), 0, kExact);
    EXPECT_NEAR((out->obstacles[i].velocity_cov - in.obstacles[i].velocity_cov).norm(), 0, kExact);
    EXPECT_NEAR(out->obstacles[i].score, in.obstacles[i].score, kFloatTol);
  }
}

TEST(MessagesTest, ParkingSlotsRoundTripInWorldAndVehicleFrames) {
  const ParkingSlotReport in = SampleSlots();
  const auto bytes = Encode(in);
  std::string why;
  const auto out = DecodeParkingSlots(bytes.data(), bytes.size(), &why);
  ASSERT_TRUE(out) << why;
  EXPECT_EQ(out->stage, ManeuverStage::kTurn);
  ASSERT_EQ(out->slots.size(), 1u);
  const ParkingSlot& a = in.slots[0];
  const ParkingSlot& b = out->slots[0];
  EXPECT_EQ(b.slot_id, 5);
  EXPECT_NEAR((a.target.position_m - b.target.position_m).norm(), 0, kExact);
  EXPECT_NEAR((a.approach.position_m - b.approach.position_m).norm(), 0, 1e-9);
  ASSERT_EQ(a.entry_path_m.size(), b.entry_path_m.size());
  EXPECT_NEAR((a.entry_path_m.back() - b.entry_path_m.back()).norm(), 0, 1e-9);
  EXPECT_NEAR(b.confidence, 0.75, kFloatTol);
  EXPECT_EQ(a.feasible, b.feasible);
  // The vehicle-frame view puts the ego at the origin facing +x.
  const ParkingSlot v = SlotInVehicleFrame(a, in.ego_world);
  const Eigen::Vector2d d = a.target.position_m - in.ego_world.position_m;
  EXPECT_NEAR(v.target.position_m.norm(), d.norm(), 1e-9);
  EXPECT_NEAR(v.target.yaw_rad, WrapAngle(a.target.yaw_rad - in.ego_world.yaw_rad), 1e-12);
}

TEST(MessagesTest, PerceptionStatusRoundTrip) {
  PerceptionStatus in;
  in.stamp_ns = 5;
  in.rigs = {{0, true, 10.0, 100, 1, 5000}, {3, false, 0.0, 90, 11, 0}};
  in.stages = {{"stereo", 120.5}, {"fusion", 3.25}};
  in.total_latency_ms = 130;
  in.malformed_messages = 2;
  in.events = {"rig 3 (rear) missing"};
  const auto bytes = Encode(in);
  std::string why;
  const auto out = DecodePerceptionStatus(bytes.data(), bytes.size(), &why);
  ASSERT_TRUE(out) << why;
  ASSERT_EQ(out->rigs.size(), 2u);
  EXPECT_FALSE(out->rigs[1].present);
  EXPECT_EQ(out->rigs[1].dropped, 11);
  EXPECT_EQ(out->stages[1].name, "fusion");
  EXPECT_NEAR(out->stages[1].latency_ms, 3.25, kFloatTol);
  EXPECT_EQ(out->events, in.events);
  EXPECT_EQ(out->malformed_messages, 2);
}

TEST(MessagesTest, RigCloudQuantisedToMillimetresAndOutOfRangeCounted) {
  RigCloud in;
  in.rig_id = 4;
  in.stamp_ns = 1'000'000'077;
  in.capture_stamp_ns = in.stamp_ns - 30'000'000;  // captured 30 ms before its set's stamp
  in.image_width_px = 782;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-30.f, 30.f);
  for (int i = 0; i < 1001; ++i) in.cloud.PushBack({u(rng), u(rng), u(rng)}, 0.01f * (i % 50), float(i % 256));
  in.cloud.PushBack({0, 0, 40.f}, 0.1f, 1.f);  // beyond +-32.767 m: cannot be held
  const auto bytes = Encode(in);
  // 3 x int16 + int16 + byte = 9 bytes per point instead of 20 as floats.
  EXPECT_LT(bytes.size(), 1001u * 9 + 200);  // + header and vehicle state
  std::string why;
  const auto out = DecodeRigCloud(bytes.data(), bytes.size(), &why);
  ASSERT_TRUE(out) << why;
  EXPECT_EQ(out->rig_id, 4);
  EXPECT_EQ(out->stamp_ns, in.stamp_ns);
  EXPECT_EQ(out->capture_stamp_ns, in.capture_stamp_ns);
  EXPECT_EQ(out->image_width_px, 782);
  ASSERT_EQ(out->cloud.size(), 1001u);
  EXPECT_EQ(out->dropped_out_of_range, 1);
  for (std::size_t i = 0; i < out->cloud.size(); ++i) {
    const auto e = (out->cloud.xyz.col(i) - in.cloud.xyz.col(i)).cwiseAbs().maxCoeff();
    ASSERT_LE(e, kQuantumM + 1e-6) << i;
    ASSERT_NEAR(out->cloud.sigma_z_m[i], in.cloud.sigma_z_m[i], kQuantumM + 1e-6);
    ASSERT_EQ(out->cloud.intensity[i], in.cloud.intensity[i]);
  }
}

TEST(MessagesTest, MalformedMessagesAreRejectedWithAReason) {
  std::string why;
  auto bytes = Encode(SampleObstacles());
  // Truncated.
  EXPECT_FALSE(DecodeObstacleList(bytes.data(), bytes.size() - 3, &why));
  EXPECT_FALSE(why.empty());
  // Wrong type.
  const auto status = Encode(PerceptionStatus{});
  EXPECT_FALSE(DecodeObstacleList(status.data(), status.size(), &why));
  // A NaN position.
  auto bad = SampleObstacles();
  bad.obstacles[1].center_m.x() = std::nan("");
  const auto nan_bytes = Encode(bad);
  EXPECT_FALSE(DecodeObstacleList(nan_bytes.data(), nan_bytes.size(), &why));
  EXPECT_NE(why.find("obstacles[1]"), std::string::npos) << why;
  // A count that claims two billion points in a small message.
  RigCloud rc;
  rc.cloud.PushBack({1, 2, 3});
  auto cloud_bytes = Encode(rc);
  cloud_bytes[40] = 0x7f;  // after hash, stamp, sequence, capture stamp, rig id, scale
  EXPECT_FALSE(DecodeRigCloud(cloud_bytes.data(), cloud_bytes.size(), &why));
  EXPECT_NE(why.find("num_points"), std::string::npos) << why;
  // A negative image width (the message's last field, big-endian int32).
  auto width_bytes = Encode(rc);
  std::fill(width_bytes.end() - 4, width_bytes.end(), std::uint8_t{0xff});
  EXPECT_FALSE(DecodeRigCloud(width_bytes.data(), width_bytes.size(), &why));
  EXPECT_NE(why.find("rig_cloud_t.image_width_px = -1 is negative"), std::string::npos) << why;
  // A rig said to have captured 2 s away from its frame set's stamp.
  rc.stamp_ns = 5'000'000'000;
  rc.capture_stamp_ns = 3'000'000'000;
  const auto far_bytes = Encode(rc);
  EXPECT_FALSE(DecodeRigCloud(far_bytes.data(), far_bytes.size(), &why));
  EXPECT_NE(why.find("capture_stamp_ns = 3000000000 is more than 1 s from the frame's stamp_ns"), std::string::npos)
      << why;
  rc.capture_stamp_ns = std::numeric_limits<std::int64_t>::min();  // no overflow in the check
  const auto min_bytes = Encode(rc);
  EXPECT_FALSE(DecodeRigCloud(min_bytes.data(), min_bytes.size(), &why));
  // A string length of 0 (LCM always counts the NUL): the generated decoder would assign
  // size_t(-1) bytes; the shared walk rejects it first. Offset 32: hash, stamp, sequence,
  // num_obstacles, track_id.
  auto empty_name = Encode(SampleObstacles());
  for (int i = 32; i < 36; ++i) empty_name[i] = 0;
  EXPECT_FALSE(DecodeObstacleList(empty_name.data(), empty_name.size(), &why));
  EXPECT_EQ(why, "obstacle_list_t.class_name = 0 does not fit a " +
                     std::to_string(empty_name.size()) + "-byte message");
  // Trailing bytes.
  bytes.push_back(0);
  EXPECT_FALSE(DecodeObstacleList(bytes.data(), bytes.size(), &why));
  EXPECT_FALSE(DecodeParkingSlots(nullptr, 0, &why));
}

TEST(MessagesTest, RandomCorruptionNeverCrashes) {
  // Flip random bytes of valid messages: every decode either succeeds or says why.
  std::mt19937 rng(11);
  const std::vector<std::vector<std::uint8_t>> valid = {Encode(SampleObstacles()), Encode(SampleSlots()),
                                                        Encode(PerceptionStatus{}), Encode(RigCloud{})};
  int rejected = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    auto b = valid[trial % valid.size()];
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    std::string why;
    const bool ok = DecodeObstacleList(b.data(), b.size(), &why).has_value() ||
                    DecodeParkingSlots(b.data(), b.size(), &why).has_value() ||
                    DecodePerceptionStatus(b.data(), b.size(), &why).has_value() ||
                    DecodeRigCloud(b.data(), b.size(), &why).has_value();
    if (!ok) ++rejected;
  }
  EXPECT_GT(rejected, 0);
}

TEST(LcmBusTest, PublishesAndReceivesOverMemq) {
  LcmBus bus("memq://");
  int received = 0;
  std::optional<ObstacleList> got;
  bus.Subscribe(kObstaclesChannel, [&](const std::string& channel, const std::uint8_t* d,
                                       std::size_t n, std::int64_t) {
    ++received;
    EXPECT_EQ(channel, kObstaclesChannel);
    got = DecodeObstacleList(d, n, nullptr);
  });
  bus.Publish(kObstaclesChannel, Encode(SampleObstacles()));
  bus.Publish(kParkingSlotsChannel, Encode(SampleSlots()));  // not subscribed
  while (bus.Handle(50)) {
  }
  EXPECT_EQ(received, 1);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->obstacles.size(), 3u);
  EXPECT_THROW(LcmBus("nosuchprovider://x"), romo::Error);
}

}  // namespace
}  // namespace romo::planning_iface
