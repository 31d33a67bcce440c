#include "romo/indoor_manip/fingerprint.hpp"

#include <algorithm>
#include <string>

#include <Eigen/Eigenvalues>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

const char* ToString(Encapsulation e) { return e == Encapsulation::kPca ? "pca" : "pln"; }

Encapsulation ParseEncapsulation(const std::string& text) {
  if (text == "pca") return Encapsulation::kPca;
  if (text == "pln") return Encapsulation::kPln;
  Fail("encapsulation must be 'pca' or 'pln', got '" + text + "'");
}

Fingerprint BuildFingerprint(const std::vector<double>& t_s,
                             const std::vector<Eigen::Vector3d>& centroids_m,
                             const InteractionPlane& plane, Encapsulation encapsulation) {
  if (t_s.size() != centroids_m.size()) {
    Fail("fingerprint: " + std::to_string(t_s.size()) + " times but " +
         std::to_string(centroids_m.size()) + " centroids");
  }
  if (t_s.size() < 2) Fail("fingerprint: need at least 2 hand positions, got " + std::to_string(t_s.size()));
  Fingerprint fp;
  fp.encapsulation = encapsulation;
  fp.projected_m.reserve(centroids_m.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& c : centroids_m) {
    fp.projected_m.push_back(plane.Project(c));
    mean += fp.projected_m.back();
  }
  mean /= static_cast<double>(centroids_m.size());
  PlaneFrame frame = PlaneAlignedFrame(plane, mean);
  if (encapsulation == Encapsulation::kPca) {
    // Principal axes of the projected path, restricted to the plane (2x2 covariance).
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& p : fp.projected_m) {
      const Eigen::Vector3d q = frame.ToFrame(p);
      cov += q.head<2>() * q.head<2>().transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
    Eigen::Vector2d major = es.eigenvectors().col(1);
    if (major.x() < 0.0) major = -major;  // keep the direction closest to the PLN x axis
    const Eigen::Vector3d x = (major.x() * frame.x_axis + major.y() * frame.y_axis).normalized();
    frame.x_axis = x;
    frame.y_axis = frame.z_axis.cross(x);
  }
  // Box centre: the middle of the extents along the chosen axes.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (const auto& p : fp.projected_m) {
    const Eigen::Vector2d q = frame.ToFrame(p).head<2>();
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Eigen::Vector2d mid = 0.5 * (lo + hi);
  frame.origin += mid.x() * frame.x_axis + mid.y() * frame.y_axis;
  fp.box_extent_m = hi - lo;
  fp.frame = frame;
  double rmin = 1e300, rmax = -1e300;
  auto& prof = fp.profiles;
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    const Eigen::Vector3d q = frame.ToFrame(fp.projected_m[i]);
    const double r = plane.Distance(centroids_m[i]);
    prof.t_s.push_back(t_s[i]);
    prof.x_m.push_back(q.x());
    prof.y_m.push_back(q.y());
    prof.r_m.push_back(r);
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
  }
  fp.box_height_m = rmax - rmin;
  return fp;
}

}  // namespace romo::indoor_manip
