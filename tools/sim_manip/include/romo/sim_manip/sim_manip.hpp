#pragma once
/// A simulated manipulation scene for the indoor plugin: an interaction plane (table or
/// whiteboard), a couple of objects and a hand-sized blob moving like a person doing an action,
/// rendered as registered RGB-D with Kinect-like depth noise and holes. Seeded and deterministic.
///
/// URI: sim-manip://ACTION?seed=N[&frames=F][&width=W][&height=H][&fps=R][&noise=0|1]
///      [&transports=T][&prop=0|1][&slide=0|1]
/// ACTION is one of romo::indoor_manip::ActionNames(). The camera looks at the hand's start
/// position, so the hand covers the image centre in frame 0 (truth().seed_px). With T > 0 the
/// hand does the action at spot A, is carried (lifted, 1 s) to spot B 30 cm away, works there,
/// and so on, alternating A and B: T transports between two location areas (Fig. 3.11).
/// prop=1 (table actions) adds a 10 x 8 x 12 cm box 32-40 cm behind the hand's start and 1-11 cm
/// to its right: where eating and drinking lift the hand to the mouth, the hand hides part of it
/// from the camera (truth().objects has its size and pose). slide=1 (table actions) adds a
/// textured 20 x 14 x 4 cm book front left of the hand's start that is pushed 10 cm right, 4 cm
/// back and turned 15 deg during the middle third of the frames (truth: its per-frame motion).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/drivers/uri.hpp"

namespace romo::sim_manip {

struct SimManipOptions {
  std::string action;
  std::uint64_t seed = 0;
  int frames = 210;
  int width_px = 320;
  int height_px = 240;
  double fps = 30.0;
  bool noise = true;  ///< depth noise, holes and colour noise
  int transports = 0;  ///< transports between two work spots (0 = the action in one place)
  bool prop = false;  ///< the extra box behind the hand's start (table actions only)
  bool slide = false;  ///< the book that moves by itself (table actions only)

  /// Reads the URI's path (action) and query; @throws romo::Error naming the key and value.
  static SimManipOptions FromUri(const drivers::Uri& uri);
  void Validate() const;
};

/// An object on the plane: a box, camera frame, as in frame 0.
struct SimObjectTruth {
  std::string name;
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();  ///< along the plane's x, y and its normal
  Eigen::Vector3d centre_camera_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes_camera = Eigen::Matrix3d::Identity();  ///< columns: the size directions
  /// Moving objects only (the slide=1 book): per frame k, its frame-0 camera-frame points into
  /// frame k's; empty for static objects.
  std::vector<Eigen::Isometry3d> T_k_0_camera;
};

struct SimManipTruth {
  /// Plane (a, b, c, d) in the camera frame, |n| = 1, camera on the positive side.
  Eigen::Vector4d plane_camera = Eigen::Vector4d::Zero();
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> hand_centre_camera_m;  ///< per frame
  std::vector<double> hand_yaw_rad;  ///< rotation about the plane normal per frame
  int seed_u_px = 0;
  int seed_v_px = 0;
  /// Three pixels on the free plane (for --plane u1,v1,u2,v2,u3,v3).
  std::vector<std::pair<int, int>> plane_pixels;
  /// Per work spot (A, then B when transports > 0): the mean of the hand centre's projection onto
  /// the plane while working there, camera frame. The location areas a perfect tracker finds.
  std::vector<Eigen::Vector3d> work_area_centres_camera_m;
  /// Frames [first, last] of each transport (the hand carried between spots).
  std::vector<std::pair<int, int>> transport_frames;
  /// The objects on the plane (then the prop when prop=1, then the book when slide=1).
  std::vector<SimObjectTruth> objects;
};

class SimManipScene {
 public:
  /// @throws romo::Error for an unknown action or invalid options.
  explicit SimManipScene(const SimManipOptions& options);
  ~SimManipScene();
  SimManipScene(const SimManipScene&) = delete;
  SimManipScene& operator=(const SimManipScene&) = delete;

  int frame_count() const;
  /// Frame @p k (0-based): rgb8 and mono16 depth (1 mm units), stamp k / fps.
  drivers::RgbdFrame Render(int k) const;
  const SimManipTruth& truth() const;
  /// One rig (id 0, "sim_manip") whose left intrinsics are the depth camera's.
  const drivers::Calibration& calibration() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Registers the "sim-manip" source scheme (idempotent).
void RegisterSimManipScheme();

}  // namespace romo::sim_manip
