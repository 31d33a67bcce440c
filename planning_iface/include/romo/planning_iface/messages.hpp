#pragma once
/// What perception tells planning, as plain types, and their LCM encoding (romo_planning.lcm).
/// The generated LCM types stay inside planning_iface: callers see bytes and plain structs.
/// Decoding validates everything (sizes, counts, finite values, ranges): a malformed message is
/// rejected with a reason, never half-read.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "romo/core/point_cloud.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/planning_iface/parking_slot.hpp"

namespace romo::planning_iface {

/// Channel names (README "Planning interface" lists them with their rates).
inline constexpr const char* kObstaclesChannel = "ROMO_OBSTACLES";
inline constexpr const char* kParkingSlotsChannel = "ROMO_PARKING_SLOTS";
inline constexpr const char* kPerceptionStatusChannel = "ROMO_PERCEPTION_STATUS";
inline constexpr const char* kRigCloudChannelPrefix = "ROMO_RIG_CLOUD";
/// "ROMO_RIG_CLOUD<k>": one stereo worker's cloud.
std::string RigCloudChannel(int rig_id);

/// One detected object in the vehicle frame.
struct Obstacle {
  int track_id = -1;  ///< -1: not tracked yet
  std::string class_name = "unknown";
  float score = 0.f;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< box centre (half height above ground)
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();    ///< length (along yaw), width, height
  double yaw_rad = 0.0;
  Eigen::Vector2d velocity_mps = Eigen::Vector2d::Zero();
  Eigen::Matrix2d velocity_cov = Eigen::Matrix2d::Zero();  ///< (m/s)^2
  int num_points = 0;
};

struct ObstacleList {
  std::int64_t stamp_ns = 0;
  std::int64_t frame_sequence = 0;
  std::vector<Obstacle> obstacles;
};

/// The parking slots of one frame. Slots are kept in the world frame; the message carries them
/// in the vehicle frame too (computed from ego_world).
struct ParkingSlotReport {
  std::int64_t stamp_ns = 0;
  std::int64_t frame_sequence = 0;
  ManeuverStage stage = ManeuverStage::kUnknown;
  Pose2 ego_world;                 ///< ego pose in the frame of `slots`
  std::vector<ParkingSlot> slots;  ///< world frame
};

/// A slot of @p report expressed in the vehicle frame (target, approach, path, axes).
ParkingSlot SlotInVehicleFrame(const ParkingSlot& slot_world, const Pose2& ego_world);

struct RigStatus {
  int rig_id = 0;
  bool present = false;
  double frame_rate_hz = 0.0;
  std::int64_t frames = 0;
  std::int64_t dropped = 0;
  int points = 0;
};

struct StageLatency {
  std::string name;
  double latency_ms = 0.0;
};

struct PerceptionStatus {
  std::int64_t stamp_ns = 0;
  std::int64_t frame_sequence = 0;
  std::vector<RigStatus> rigs;
  std::vector<StageLatency> stages;
  double total_latency_ms = 0.0;
  std::int64_t frames_processed = 0;
  std::int64_t frames_dropped = 0;
  std::int64_t malformed_messages = 0;
  std::vector<std::string> events;  ///< e.g. "rig 3 (rear) missing for 0.5 s"
};

/// One rig's cloud as a stereo worker publishes it (vehicle frame).
struct RigCloud {
  std::int64_t stamp_ns = 0;  ///< the frame set's (frames are assembled by it)
  std::int64_t frame_sequence = 0;
  /// The rig's own capture instant: rigs of one set may be up to half a frame period apart, and
  /// fusion motion-compensates each to the set's stamp. Within kMaxCaptureOffsetNs of stamp_ns.
  std::int64_t capture_stamp_ns = 0;
  int rig_id = 0;
  PointCloud cloud;
  int dropped_out_of_range = 0;  ///< points the compact encoding could not hold
  double stereo_ms = 0.0;
  std::optional<drivers::VehicleState> vehicle;  ///< odometry of the frame, when known
  int image_width_px = 0;  ///< of the images the cloud was matched from (0: not said)
};

/// How far a rig's capture may lie from its frame set's stamp in a valid RigCloud.
inline constexpr std::int64_t kMaxCaptureOffsetNs = 1'000'000'000;

std::vector<std::uint8_t> Encode(const ObstacleList& list);
std::vector<std::uint8_t> Encode(const ParkingSlotReport& report);
std::vector<std::uint8_t> Encode(const PerceptionStatus& status);
/// Quantises positions and sigma to @p scale_m (default 1 mm); points beyond the int16 range
/// are left out and counted in dropped_out_of_range.
std::vector<std::uint8_t> Encode(const RigCloud& cloud, double scale_m = 0.001);

/// Each returns nullopt for a malformed message and says why in @p why (may be null).
std::optional<ObstacleList> DecodeObstacleList(const void* data, std::size_t size, std::string* why);
std::optional<ParkingSlotReport> DecodeParkingSlots(const void* data, std::size_t size,
                                                    std::string* why);
std::optional<PerceptionStatus> DecodePerceptionStatus(const void* data, std::size_t size,
                                                       std::string* why);
std::optional<RigCloud> DecodeRigCloud(const void* data, std::size_t size, std::string* why);

}  // namespace romo::planning_iface
