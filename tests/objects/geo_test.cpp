// Local ENU <-> WGS84 round trips through GeographicLib.
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/geo.hpp"

namespace romo::objects {
namespace {

constexpr double kRoundTripM = 1e-3;  // the bound: 1 mm
constexpr double kMetresPerDegLat = 111320.0;

TEST(GeoTest, EnuWgs84RoundTripWithinOneMillimetre) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-5000.0, 5000.0);  // a 10 km test area
  std::uniform_real_distribution<double> up(-50.0, 50.0);
  // Oberpfaffenhofen (RoMo's home), near the pole, at the date line, south of the equator.
  const Wgs84 origins[] = {{48.0833, 11.2833, 600.0}, {78.2, 15.6, 10.0}, {-33.9, 179.999, 0.0}};
  for (const Wgs84& origin : origins) {
    const LocalEnu enu(origin);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d p(offset(rng), offset(rng), up(rng));
      const Eigen::Vector3d back = enu.ToEnu(enu.ToWgs84(p));
      EXPECT_LT((back - p).norm(), kRoundTripM);
      // And the other way: WGS84 -> ENU -> WGS84, compared in metres.
      const Wgs84 w = enu.ToWgs84(p);
      const Wgs84 w2 = enu.ToWgs84(enu.ToEnu(w));
      EXPECT_LT(std::abs(w2.latitude_deg - w.latitude_deg) * kMetresPerDegLat, kRoundTripM);
      EXPECT_LT(std::abs(w2.altitude_m - w.altitude_m), kRoundTripM);
    }
  }
}

TEST(GeoTest, EastAndNorthPointTheRightWay) {
  const LocalEnu enu({48.0, 11.0, 500.0});
  const Wgs84 north = enu.ToWgs84(Eigen::Vector3d(0.0, 1000.0, 0.0));
  const Wgs84 east = enu.ToWgs84(Eigen::Vector3d(1000.0, 0.0, 0.0));
  EXPECT_GT(north.latitude_deg, 48.0);
  EXPECT_NEAR(north.longitude_deg, 11.0, 1e-9);
  EXPECT_GT(east.longitude_deg, 11.0);
  // 1 km north is ~0.009 deg of latitude (WGS84 meridian arc at 48 deg: 111.2 km/deg).
  EXPECT_NEAR((north.latitude_deg - 48.0) * 111200.0, 1000.0, 2.0);
}

TEST(GeoTest, VehiclePoseFromGnssFix) {
  const LocalEnu enu({48.0, 11.0, 500.0});
  drivers::GnssFix fix;
  fix.valid = true;
  const Wgs84 w = enu.ToWgs84(Eigen::Vector3d(10.0, 20.0, 0.0));
  fix.latitude_deg = w.latitude_deg;
  fix.longitude_deg = w.longitude_deg;
  fix.altitude_m = w.altitude_m;
  const Eigen::Isometry3d T = VehiclePoseInEnu(enu, fix, M_PI / 2);  // facing north
  // 1 m ahead of the vehicle is 1 m north of it.
  const Eigen::Vector3d ahead = T * Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_LT((ahead - Eigen::Vector3d(10.0, 21.0, 0.0)).norm(), kRoundTripM);
  fix.valid = false;
  EXPECT_THROW(VehiclePoseInEnu(enu, fix, 0.0), romo::Error);
}

TEST(GeoTest, RejectsInvalidOrigin) {
  EXPECT_THROW(LocalEnu({95.0, 0.0, 0.0}), romo::Error);
  EXPECT_THROW(LocalEnu({std::nan(""), 0.0, 0.0}), romo::Error);
}

}  // namespace
}  // namespace romo::objects
