#pragma once
/// The seeded parking scene: a row of perpendicular-parked cars with free bays of varying width
/// (one wide enough for the ego vehicle, one too narrow), bay lines, a curb and a hedge,
/// pedestrians walking to goals (with the total and partial occlusions of dissertation
/// Fig. 4.16), and the ego vehicle's parking maneuver (approach, turn on the spot, sideways entry).
/// Same seed, same scene. World frame: x east, y north, z up; the row runs along x.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/sim/ground_truth.hpp"

namespace romo::sim {

/// How a surface looks (procedural texture family).
enum class Material : std::uint8_t { kAsphalt, kCurb, kHedge, kCar, kPedestrian };

/// An object as the renderer sees it: its truth box plus its appearance.
struct SceneObject {
  GtBox box;
  Material material = Material::kCar;
  float albedo = 0.5f;              ///< mean reflectance 0..1
  std::uint32_t texture_seed = 0;   ///< decorrelates the textures of objects
};

/// A painted line on the ground: a rectangle of the given width from a to b.
struct PaintLine {
  Eigen::Vector2d a_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d b_m = Eigen::Vector2d::Zero();
  double width_m = 0.12;
};

/// The ego vehicle at one instant.
struct EgoState {
  Eigen::Isometry3d T_world_vehicle = Eigen::Isometry3d::Identity();
  double speed_mps = 0.0;
  double yaw_rate_radps = 0.0;
  std::string phase;
};

/// A pedestrian's walk: straight legs between waypoints at a fixed speed, with a pause at each.
struct PedestrianScript {
  int id = 0;
  Eigen::Vector3d size_m = Eigen::Vector3d(0.4, 0.5, 1.75);  ///< depth, shoulder width, height
  std::vector<Eigen::Vector2d> waypoints_m;  ///< first = start
  std::vector<double> pause_s;               ///< pause on reaching waypoint k (k >= 1)
  double start_s = 0.0;                      ///< waits at the start until then
  double speed_mps = 1.2;
  float albedo = 0.4f;
};

/// Everything the renderer needs at one instant.
struct SceneSnapshot {
  double time_s = 0.0;
  EgoState ego;
  std::vector<SceneObject> objects;  ///< static structures, cars and pedestrians
  const std::vector<PaintLine>* lines = nullptr;
  std::uint32_t ground_seed = 0;
};

struct ParkingSceneParams {
  std::uint64_t seed = 1;
  /// Ego vehicle footprint (RoMo): length 2.8 m, width 1.6 m; height for the truth box.
  Eigen::Vector3d ego_size_m = Eigen::Vector3d(2.8, 1.6, 1.9);
  /// Free space required on each side of the ego vehicle in a bay (sideways entry: along its
  /// length), so a bay is feasible when width >= length + 2 * margin (3.2 m).
  double bay_side_margin_m = 0.2;
  void Validate() const;
};

class ParkingScene {
 public:
  explicit ParkingScene(const ParkingSceneParams& params);

  /// Scene state at @p time_s seconds after the start.
  SceneSnapshot At(double time_s) const;
  /// Ego state only (cheap).
  EgoState EgoAt(double time_s) const;
  /// Truth boxes at @p time_s (static structures, cars, pedestrians with velocities).
  std::vector<GtBox> ObjectsAt(double time_s) const;

  const std::vector<GtBay>& bays() const { return bays_; }
  const std::vector<PaintLine>& lines() const { return lines_; }
  const std::vector<PedestrianScript>& pedestrians() const { return pedestrians_; }
  const ParkingSceneParams& params() const { return params_; }
  /// Duration of the whole maneuver; the vehicle stays parked afterwards.
  double maneuver_duration_s() const;
  /// Ids of the pedestrian pairs scripted to occlude each other (near, far): the first walks
  /// in single file in front of the second (total occlusion), the second side by side (partial).
  std::pair<int, int> total_occlusion_pair() const { return {11, 12}; }
  std::pair<int, int> partial_occlusion_pair() const { return {13, 14}; }

 private:
  void BuildStatic();
  void BuildPedestrians();

  ParkingSceneParams params_;
  std::vector<SceneObject> static_objects_;
  std::vector<PaintLine> lines_;
  std::vector<GtBay> bays_;
  std::vector<PedestrianScript> pedestrians_;
  std::vector<float> pedestrian_albedo_;
  Eigen::Vector2d bay_center_m_ = Eigen::Vector2d::Zero();  ///< the wide bay the ego parks in
  double spot_y_m_ = 0.0;
  double start_y_m_ = 0.0;
  double final_y_m_ = 0.0;
};

/// Pose of @p script's pedestrian at @p time_s: position (x, y), heading and velocity.
struct PedestrianState {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_mps = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;
};
PedestrianState EvaluatePedestrian(const PedestrianScript& script, double time_s);

}  // namespace romo::sim
