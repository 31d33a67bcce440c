#pragma once
/// Location (functional) areas on the interaction plane (dissertation Sec. 3.3, Fig. 3.11): the
/// places where the hand dwells to do its work, and the ends of transport paths, i.e. where the
/// projected hand path stops after (or starts before) a transport between two such places.
///
/// The projected path is split into stays (the hand remains within stay_radius_m of the stay's
/// first sample for at least min_stay_s) and the moves between them. A move whose two stays lie
/// at least min_transport_m apart is a transport; it starts where the path leaves the core of the
/// stay it comes from and stops where it enters the core of the next one. Stays are clustered by
/// single linkage (cluster_link_m): one cluster = one area; each transport end marks the area it
/// starts from or stops in (sources "transport_start" / "transport_end").
#include <string>
#include <vector>

#include <Eigen/Core>

#include "romo/indoor_manip/fingerprint.hpp"

namespace romo::indoor_manip {

struct LocationParams {
  /// A stay: every sample within this distance (in the plane) of the stay's first sample, metres.
  /// 8 cm holds a hand working in place (tightening, hammering) but not a writing row.
  double stay_radius_m = 0.08;
  /// ... for at least this long, seconds.
  double min_stay_s = 0.6;
  /// Two consecutive stays this far apart (centroids, metres) are joined by a transport.
  double min_transport_m = 0.15;
  /// Candidates closer than this (metres) belong to the same area (single linkage).
  double cluster_link_m = 0.10;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// One transport: the path between two stays.
struct Transport {
  int start_sample = 0;  ///< the path starts moving here (last sample in the left stay's core)
  int end_sample = 0;    ///< the path stops here (first sample in the reached stay's core)
  Eigen::Vector2d start_xy_m = Eigen::Vector2d::Zero();  ///< fingerprint frame
  Eigen::Vector2d end_xy_m = Eigen::Vector2d::Zero();
  double length_m = 0.0;  ///< in-plane path length
  double duration_s = 0.0;
  int from_area = -1;  ///< indices into LocationAnalysis::areas
  int to_area = -1;
};

struct LocationArea {
  Eigen::Vector2d centre_xy_m = Eigen::Vector2d::Zero();  ///< fingerprint frame
  Eigen::Vector3d centre_camera_m = Eigen::Vector3d::Zero();  ///< on the plane, camera frame
  double radius_m = 0.0;  ///< 90th percentile distance of its samples from the centre
  double dwell_s = 0.0;   ///< time the hand stayed in it
  int stays = 0;
  int transport_starts = 0;  ///< transports leaving it
  int transport_ends = 0;    ///< transports arriving in it
  /// "stay", "transport_end", "transport_start" or "path" (no stay: the whole path is one area).
  std::vector<std::string> sources;
};

struct LocationAnalysis {
  std::vector<LocationArea> areas;
  std::vector<Transport> transports;
  int stays = 0;
};

/// Location areas and transports of @p fingerprint (its profiles' x, y and its frame).
/// A path with fewer than 2 samples gives no area.
/// @throws romo::Error for invalid @p params.
LocationAnalysis FindLocationAreas(const Fingerprint& fingerprint, const LocationParams& params);

}  // namespace romo::indoor_manip
