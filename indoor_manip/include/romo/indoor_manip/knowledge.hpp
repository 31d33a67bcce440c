#pragma once
/// The knowledge container (dissertation Sec. 4.1.1, Fig. 4.1): what the geometric layer and the
/// plugin know about the scene and the action, in three areas — physics (the interaction plane
/// and the objects on it with their PCA boxes, completed over time by the blob map), motions (the hand path, its motion features, the
/// transports, independent object motions) and locations (the location areas) — plus the action
/// label linked to the object functions of the Atlas that explain it.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/indoor_manip/action_label.hpp"
#include "romo/indoor_manip/interaction_plane.hpp"
#include "romo/indoor_manip/location_areas.hpp"
#include "romo/indoor_manip/object_map.hpp"
#include "romo/indoor_manip/object_functions.hpp"
#include "romo/indoor_manip/scene_objects.hpp"

namespace romo::indoor_manip {

struct ManipResult;

struct KnowledgeContainer {
  struct Physics {
    InteractionPlane plane;
    int plane_inliers = 0;
    std::vector<SceneObject> objects;
    /// The blob map's objects over all frames: an object of the first frame carries the one it
    /// started (CompletedObject::first_frame_object), the others are listed as later objects.
    std::vector<CompletedObject> completed;
    ObjectMapStats map;
  } physics;
  struct Motions {
    int frames = 0;
    int frames_with_hand = 0;
    double duration_s = 0.0;
    double hand_path_length_m = 0.0;  ///< 3D length of the corrected hand path
    Eigen::Vector2d fingerprint_extent_m = Eigen::Vector2d::Zero();
    double fingerprint_height_m = 0.0;
    Eigen::Vector3d cumulative_rotation_deg = Eigen::Vector3d::Zero();  ///< about hand x, y, z
    ActionFeatures features;
    std::vector<Transport> transports;
    std::vector<ObjectMotion> object_motions;
  } motions;
  struct Locations {
    std::vector<LocationArea> areas;
  } locations;
  struct Action {
    std::string label;
    std::vector<std::string> reasons;
    /// Atlas functions with this label: which objects perform the action and how.
    std::vector<ObjectFunction> functions;
  } action;

  /// {"physics": {...}, "motions": {...}, "locations": {...}, "action": {...}}
  std::string ToJson() const;
};

/// Fills the container from a finished analysis and the Atlas of object functions.
KnowledgeContainer BuildKnowledge(const ManipResult& result, const ObjectFunctionAtlas& atlas);

}  // namespace romo::indoor_manip
