#pragma once
/// Local ENU <-> WGS84 for logs (GeographicLib LocalCartesian behind a pimpl).
#include <memory>

#include <Eigen/Geometry>

#include "romo/drivers/frames.hpp"

namespace romo::objects {

struct Wgs84 {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;  ///< ellipsoidal height
};

/// A local east-north-up frame tangent at a fixed geodetic origin.
class LocalEnu {
 public:
  /// @throws romo::Error when the origin is not a valid latitude/longitude/height.
  explicit LocalEnu(const Wgs84& origin);
  ~LocalEnu();
  LocalEnu(const LocalEnu& other);
  LocalEnu& operator=(const LocalEnu& other);

  /// WGS84 -> ENU metres. @throws romo::Error for an invalid position.
  Eigen::Vector3d ToEnu(const Wgs84& position) const;
  /// ENU metres -> WGS84.
  Wgs84 ToWgs84(const Eigen::Vector3d& enu_m) const;
  const Wgs84& origin() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// The vehicle's pose in local ENU from a GNSS fix (taken at the vehicle origin) and its heading
/// (yaw of the vehicle x axis about up, counter-clockwise from east).
/// @throws romo::Error when the fix is marked invalid or not finite.
Eigen::Isometry3d VehiclePoseInEnu(const LocalEnu& enu, const drivers::GnssFix& fix,
                                   double heading_enu_rad);

}  // namespace romo::objects
