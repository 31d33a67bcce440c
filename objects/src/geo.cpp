#include "romo/objects/geo.hpp"

#include <cmath>
#include <sstream>

#include <GeographicLib/LocalCartesian.hpp>

#include "romo/core/check.hpp"

namespace romo::objects {
namespace {

void CheckWgs84(const char* what, const Wgs84& p) {
  if (!(std::abs(p.latitude_deg) <= 90.0) || !(std::abs(p.longitude_deg) <= 540.0) ||
      !std::isfinite(p.altitude_m)) {
    std::ostringstream m;
    m.precision(12);
    m << what << ": invalid WGS84 position (latitude " << p.latitude_deg << " deg, longitude "
      << p.longitude_deg << " deg, altitude " << p.altitude_m << " m)";
    Fail(m.str());
  }
}

}  // namespace

class LocalEnu::Impl {
 public:
  explicit Impl(const Wgs84& o)
      : origin(o), cartesian(o.latitude_deg, o.longitude_deg, o.altitude_m) {}
  Wgs84 origin;
  GeographicLib::LocalCartesian cartesian;
};

LocalEnu::LocalEnu(const Wgs84& origin) {
  CheckWgs84("LocalEnu origin", origin);
  impl_ = std::make_unique<Impl>(origin);
}
LocalEnu::~LocalEnu() = default;
LocalEnu::LocalEnu(const LocalEnu& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
LocalEnu& LocalEnu::operator=(const LocalEnu& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}

Eigen::Vector3d LocalEnu::ToEnu(const Wgs84& p) const {
  CheckWgs84("LocalEnu::ToEnu", p);
  Eigen::Vector3d enu;
  impl_->cartesian.Forward(p.latitude_deg, p.longitude_deg, p.altitude_m, enu.x(), enu.y(), enu.z());
  return enu;
}

Wgs84 LocalEnu::ToWgs84(const Eigen::Vector3d& enu_m) const {
  ROMO_THROW_UNLESS(enu_m.allFinite());
  Wgs84 p;
  impl_->cartesian.Reverse(enu_m.x(), enu_m.y(), enu_m.z(), p.latitude_deg, p.longitude_deg,
                           p.altitude_m);
  return p;
}

const Wgs84& LocalEnu::origin() const { return impl_->origin; }

Eigen::Isometry3d VehiclePoseInEnu(const LocalEnu& enu, const drivers::GnssFix& fix,
                                   double heading_enu_rad) {
  if (!fix.valid) Fail("VehiclePoseInEnu: GNSS fix at stamp " + std::to_string(fix.stamp_ns) + " ns is marked invalid");
  if (!std::isfinite(heading_enu_rad)) Fail("VehiclePoseInEnu: heading is not finite");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(heading_enu_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = enu.ToEnu({fix.latitude_deg, fix.longitude_deg, fix.altitude_m});
  return T;
}

}  // namespace romo::objects
