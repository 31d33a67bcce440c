#include "romo/mapping/blob_map.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "romo/core/check.hpp"

namespace romo::mapping {

Aabb Aabb::Of(const Eigen::Matrix3Xd& xyz, double margin_m) {
  Aabb b;
  for (Eigen::Index i = 0; i < xyz.cols(); ++i) {
    b.lo = b.lo.cwiseMin(xyz.col(i));
    b.hi = b.hi.cwiseMax(xyz.col(i));
  }
  b.lo.array() -= margin_m;
  b.hi.array() += margin_m;
  return b;
}

Obb Obb::Of(const Eigen::Matrix3Xd& xyz, double margin_m) {
  Obb b;
  if (xyz.cols() == 0) {
    b.half_m.setConstant(margin_m);
    return b;
  }
  const Eigen::Vector3d mean = xyz.rowwise().mean();
  const Eigen::Matrix3Xd c = xyz.colwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c * c.transpose());
  b.axes = es.eigenvectors();  // orthonormal columns
  const Eigen::Matrix3Xd local = b.axes.transpose() * c;
  const Eigen::Vector3d lo = local.rowwise().minCoeff(), hi = local.rowwise().maxCoeff();
  b.center = mean + b.axes * (0.5 * (lo + hi));
  b.half_m = (0.5 * (hi - lo)).array() + margin_m;
  return b;
}

bool Obb::Intersects(const Obb& o) const {
  // Gottschalk's OBBTree test: B's axes in A's frame, R(i, j) = a_i . b_j.
  const Eigen::Matrix3d R = axes.transpose() * o.axes;
  // Parallel edges make the cross products near zero: a small epsilon keeps the test robust.
  const Eigen::Matrix3d absR = R.cwiseAbs().array() + 1e-12;
  const Eigen::Vector3d t = axes.transpose() * (o.center - center);
  const Eigen::Vector3d& a = half_m;
  const Eigen::Vector3d& b = o.half_m;
  for (int i = 0; i < 3; ++i) {  // A's face normals
    if (std::abs(t[i]) > a[i] + b.dot(absR.row(i))) return false;
  }
  for (int j = 0; j < 3; ++j) {  // B's face normals
    if (std::abs(t.dot(R.col(j))) > a.dot(absR.col(j)) + b[j]) return false;
  }
  for (int i = 0; i < 3; ++i) {  // a_i x b_j
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = a[i1] * absR(i2, j) + a[i2] * absR(i1, j);
      const double rb = b[j1] * absR(i, j2) + b[j2] * absR(i, j1);
      if (std::abs(t[i2] * R(i1, j) - t[i1] * R(i2, j)) > ra + rb) return false;
    }
  }
  return true;
}

std::vector<std::pair<int, int>> IntersectBlobs(const std::vector<Obb>& stored,
                                                const std::vector<Obb>& fresh) {
  std::vector<std::pair<int, int>> out;
  for (int j = 0; j < static_cast<int>(stored.size()); ++j) {
    for (int i = 0; i < static_cast<int>(fresh.size()); ++i) {
      if (stored[j].Intersects(fresh[i])) out.emplace_back(j, i);
    }
  }
  return out;
}

void PinholeCamera::Validate() const {
  if (!(fx_px > 0 && fy_px > 0) || width_px <= 0 || height_px <= 0) {
    Fail("blob map camera: fx, fy, width, height must be positive, got fx=" + std::to_string(fx_px) +
         " fy=" + std::to_string(fy_px) + " size " + std::to_string(width_px) + "x" +
         std::to_string(height_px));
  }
}

std::vector<int> Blob::ConfidentPoints(const ConfidenceParams& params, double min_cv) const {
  std::vector<int> out;
  for (std::size_t i = 0; i < evidence.size(); ++i) {
    if (ConfidenceValue(evidence[i], params) >= min_cv) out.push_back(static_cast<int>(i));
  }
  return out;
}

void BlobMapParams::Validate() const {
  if (!(chi2_gate > 0)) Fail("blob_map.chi2_gate must be > 0, got " + std::to_string(chi2_gate));
  if (search_radius_px < 0) Fail("blob_map.search_radius_px must be >= 0, got " + std::to_string(search_radius_px));
  if (!(occlusion_margin_m > 0)) Fail("blob_map.occlusion_margin_m must be > 0, got " + std::to_string(occlusion_margin_m));
  confidence.Validate();
  rigid.Validate();
}

BlobMap::BlobMap(const BlobMapParams& params) : params_(params) { params_.Validate(); }

namespace {

struct Projection {
  int u = -1, v = -1;
  double z = 0;
};

Projection Project(const PinholeCamera& cam, const Eigen::Isometry3d& T_cam_world,
                   const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d p = T_cam_world * p_world;
  Projection pr;
  if (!(p.z() > 1e-6)) return pr;
  const int u = static_cast<int>(std::lround(cam.fx_px * p.x() / p.z() + cam.cx_px));
  const int v = static_cast<int>(std::lround(cam.fy_px * p.y() / p.z() + cam.cy_px));
  if (u < 0 || v < 0 || u >= cam.width_px || v >= cam.height_px) return pr;
  pr.u = u;
  pr.v = v;
  pr.z = p.z();
  return pr;
}

// Squared Mahalanobis distance of the innovation @p nu with covariance @p S (eq. 3.4).
double Chi2(const Eigen::Vector3d& nu, const Eigen::Matrix3d& S) { return nu.dot(S.ldlt().solve(nu)); }

}  // namespace

BlobMapUpdate BlobMap::Update(const std::vector<ObservedBlob>& fresh, const PinholeCamera& cam,
                              const std::vector<float>& depth_m) {
  cam.Validate();
  const int w = cam.width_px, h = cam.height_px;
  if (!depth_m.empty() && depth_m.size() != static_cast<std::size_t>(w) * h) {
    Fail("blob map: depth image has " + std::to_string(depth_m.size()) + " pixels, camera " +
         std::to_string(w) + "x" + std::to_string(h));
  }
  for (const auto& b : fresh) {
    if (b.cov_world.size() != static_cast<std::size_t>(b.xyz_world.cols())) {
      Fail("blob map: observed blob with " + std::to_string(b.xyz_world.cols()) + " points and " +
           std::to_string(b.cov_world.size()) + " covariances");
    }
  }
  BlobMapUpdate out;
  const Eigen::Isometry3d T_cam_world = cam.T_world_camera.inverse();

  // Alg. 1 intersection search.
  std::vector<Obb> stored_boxes, fresh_boxes;
  for (const auto& b : blobs_) stored_boxes.push_back(Obb::Of(b.xyz_world, params_.box_margin_m));
  for (const auto& b : fresh) fresh_boxes.push_back(Obb::Of(b.xyz_world, params_.box_margin_m));
  const auto pairs = IntersectBlobs(stored_boxes, fresh_boxes);
  out.intersections = static_cast<int>(pairs.size());

  // Current observations bucketed by pixel (eq. 3.6): the nearest observed point per pixel.
  const std::size_t npx = static_cast<std::size_t>(w) * h;
  std::vector<std::pair<int, int>> obs_at(npx, {-1, -1});  // (fresh blob, point)
  std::vector<double> obs_z(npx, std::numeric_limits<double>::infinity());
  for (int i = 0; i < static_cast<int>(fresh.size()); ++i) {
    for (Eigen::Index q = 0; q < fresh[i].xyz_world.cols(); ++q) {
      const Projection pr = Project(cam, T_cam_world, fresh[i].xyz_world.col(q));
      if (pr.u < 0) continue;
      const std::size_t px = static_cast<std::size_t>(pr.v) * w + pr.u;
      if (pr.z < obs_z[px]) {
        obs_z[px] = pr.z;
        obs_at[px] = {i, static_cast<int>(q)};
      }
    }
  }
  // Stored points z-buffered into the current camera (eq. 3.7): only the front-most per pixel
  // is visible.
  std::vector<std::pair<int, int>> zbuf(npx, {-1, -1});
  std::vector<double> zbuf_z(npx, std::numeric_limits<double>::infinity());
  std::vector<std::vector<Projection>> proj(blobs_.size());
  for (int j = 0; j < static_cast<int>(blobs_.size()); ++j) {
    proj[j].resize(blobs_[j].size());
    for (std::size_t q = 0; q < blobs_[j].size(); ++q) {
      const Projection pr = Project(cam, T_cam_world, blobs_[j].xyz_world.col(q));
      proj[j][q] = pr;
      if (pr.u < 0) continue;
      const std::size_t px = static_cast<std::size_t>(pr.v) * w + pr.u;
      if (pr.z < zbuf_z[px]) {
        zbuf_z[px] = pr.z;
        zbuf[px] = {j, static_cast<int>(q)};
      }
    }
  }

  std::vector<std::vector<char>> fresh_used(fresh.size());
  for (std::size_t i = 0; i < fresh.size(); ++i) fresh_used[i].assign(fresh[i].xyz_world.cols(), 0);
  std::vector<char> fresh_merged(fresh.size(), 0);
  const int r = params_.search_radius_px;
  // Whether a stored point of blob @p j, front-most in the pixel neighbourhood of @p pr, lies
  // within the gate of the observation (@p x, @p cov).
  const auto near_stored_point = [&](int j, const Projection& pr, const Eigen::Vector3d& x,
                                     const Eigen::Matrix3d& cov) {
    if (pr.u < 0) return false;
    const Blob& blob = blobs_[j];
    for (int dv = -r; dv <= r; ++dv) {
      for (int du = -r; du <= r; ++du) {
        const int u = pr.u + du, v = pr.v + dv;
        if (u < 0 || v < 0 || u >= w || v >= h) continue;
        const auto [sj, sq] = zbuf[static_cast<std::size_t>(v) * w + u];
        if (sj == j && Chi2(x - blob.xyz_world.col(sq), blob.cov_world[sq] + cov) < params_.chi2_gate) return true;
      }
    }
    return false;
  };

  for (int j = 0; j < static_cast<int>(blobs_.size()); ++j) {
    Blob& blob = blobs_[j];
    std::vector<char> candidate(fresh.size(), 0);
    bool any = false;
    for (const auto& [sj, fi] : pairs) {
      if (sj == j) {
        candidate[fi] = 1;
        any = true;
      }
    }
    // Matches are only pending until the rigid check: a blob update is all or nothing.
    struct Pending {
      int q = 0, fi = 0, fq = 0;
      Eigen::Vector3d fused;
      Eigen::Matrix3d cov;
    };
    std::vector<Pending> pending;
    for (std::size_t q = 0; q < blob.size(); ++q) {
      const Projection& pr = proj[j][q];
      if (pr.u < 0) continue;  // out of view: case 4, unchanged
      const std::size_t px = static_cast<std::size_t>(pr.v) * w + pr.u;
      const bool front = zbuf[px].first == j && zbuf[px].second == static_cast<int>(q);
      // Mahalanobis association in the pixel neighbourhood (eqs. 3.3-3.5).
      int best_i = -1, best_q = -1;
      double best = params_.chi2_gate;
      if (any && front) {
        const Eigen::Vector3d& pred = blob.xyz_world.col(q);
        for (int dv = -r; dv <= r; ++dv) {
          for (int du = -r; du <= r; ++du) {
            const int u = pr.u + du, v = pr.v + dv;
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            const auto [fi, fq] = obs_at[static_cast<std::size_t>(v) * w + u];
            if (fi < 0 || !candidate[fi] || fresh_used[fi][fq]) continue;
            const Eigen::Vector3d nu = fresh[fi].xyz_world.col(fq) - pred;
            const double chi2 = Chi2(nu, blob.cov_world[q] + fresh[fi].cov_world[fq]);
            if (chi2 < best) {
              best = chi2;
              best_i = fi;
              best_q = fq;
            }
          }
        }
      }
      if (best_i >= 0) {
        // Kalman fusion (eqs. 3.8-3.10) with H = I; committed after the rigid check.
        const Eigen::Matrix3d& P = blob.cov_world[q];
        const Eigen::Matrix3d S = P + fresh[best_i].cov_world[best_q];
        const Eigen::Matrix3d K = P * S.inverse();
        Pending m;
        m.q = static_cast<int>(q);
        m.fi = best_i;
        m.fq = best_q;
        m.fused = blob.xyz_world.col(q) + K * (fresh[best_i].xyz_world.col(best_q) - blob.xyz_world.col(q));
        m.cov = P - K * P;
        pending.push_back(m);
        fresh_used[best_i][best_q] = 1;  // one stored point per observation, also while pending
        continue;
      }
      // Not matched: unobserved prediction if it should have been seen (front-most and nothing
      // observed clearly in front of it), otherwise occluded (case 4).
      bool occluded = !front;
      if (!occluded && !depth_m.empty()) {
        const float d = depth_m[px];
        occluded = d > 0.f && d < pr.z - params_.occlusion_margin_m;
      }
      if (!occluded) {
        UpdateEvidence(Visibility::kUnobservedPrediction, &blob.evidence[q]);
        ++out.unobserved;
      }
    }
    // Rigid check (eq. 3.11): the transform from the stored matched points to the fused ones,
    // applied to every point of the blob, so occluded parts follow the update. Only its inliers
    // are fused (position, covariance, support); when it fails (fewer than rigid.min_inliers
    // consistent matches) the blob keeps its points, covariances and evidence as they were and
    // the observations stay free for the other candidates or a new blob.
    std::optional<RigidMotion> rigid;
    if (!pending.empty()) {
      MatchedPoints3D m;
      m.p1.resize(3, static_cast<Eigen::Index>(pending.size()));
      m.p2.resize(3, static_cast<Eigen::Index>(pending.size()));
      for (std::size_t i = 0; i < pending.size(); ++i) {
        m.p1.col(i) = blob.xyz_world.col(pending[i].q);
        m.p2.col(i) = pending[i].fused;
        m.cov1.push_back(blob.cov_world[pending[i].q]);
        m.cov2.push_back(pending[i].cov);
      }
      rigid = EstimateRigidMotion(m, params_.rigid);
    }
    std::vector<char> is_inlier(pending.size(), 0);
    if (rigid) {
      for (int i : rigid->inliers) is_inlier[i] = 1;
      for (std::size_t q = 0; q < blob.size(); ++q) blob.xyz_world.col(q) = rigid->T_2_1 * blob.xyz_world.col(q).eval();
      out.corrections.emplace_back(blob.id, rigid->T_2_1);
    }
    for (std::size_t i = 0; i < pending.size(); ++i) {
      const Pending& m = pending[i];
      if (!is_inlier[i]) {
        fresh_used[m.fi][m.fq] = 0;
        continue;
      }
      blob.xyz_world.col(m.q) = m.fused;
      blob.cov_world[m.q] = m.cov;
      UpdateEvidence(Visibility::kMatched, &blob.evidence[m.q]);
      fresh_merged[m.fi] = 1;
      ++out.matched;
    }
    // Unmatched points of the fresh blobs fused here are unpredicted observations: added, unless
    // a stored point of this blob in the pixel neighbourhood lies within the gate (it matched a
    // neighbouring observation): the surface is already there, and a copy would only hide it in
    // the next frame's z-buffer and never gain support.
    std::vector<std::pair<int, Eigen::Index>> added;
    for (std::size_t i = 0; i < fresh.size(); ++i) {
      if (!candidate[i] || !fresh_merged[i]) continue;
      for (Eigen::Index q = 0; q < fresh[i].xyz_world.cols(); ++q) {
        if (fresh_used[i][q]) continue;
        fresh_used[i][q] = 1;
        const Eigen::Vector3d& x = fresh[i].xyz_world.col(q);
        if (near_stored_point(j, Project(cam, T_cam_world, x), x, fresh[i].cov_world[q])) {
          ++out.redundant;
          continue;
        }
        added.emplace_back(static_cast<int>(i), q);
      }
    }
    const Eigen::Index n0 = blob.xyz_world.cols();
    blob.xyz_world.conservativeResize(3, n0 + static_cast<Eigen::Index>(added.size()));
    for (std::size_t a = 0; a < added.size(); ++a) {
      const auto [i, q] = added[a];
      blob.xyz_world.col(n0 + static_cast<Eigen::Index>(a)) = fresh[i].xyz_world.col(q);
      blob.cov_world.push_back(fresh[i].cov_world[q]);
      PointEvidence e;
      UpdateEvidence(Visibility::kUnpredictedObservation, &e);
      blob.evidence.push_back(e);
      ++out.unpredicted;
    }
  }
  // Fresh blobs that matched nothing become new stored blobs.
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    if (fresh_merged[i] || fresh[i].xyz_world.cols() == 0) continue;
    Blob b;
    b.id = next_id_++;
    b.xyz_world = fresh[i].xyz_world;
    b.cov_world = fresh[i].cov_world;
    b.evidence.assign(b.size(), PointEvidence{1, 0});
    out.unpredicted += static_cast<int>(b.size());
    blobs_.push_back(std::move(b));
    ++out.new_blobs;
  }
  return out;
}

}  // namespace romo::mapping
