#include "romo/indoor_manip/location_areas.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {
namespace {

struct Stay {
  int first = 0, last = 0;  // samples, inclusive
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
};

void AddSource(LocationArea* a, const std::string& s) {
  if (std::find(a->sources.begin(), a->sources.end(), s) == a->sources.end()) a->sources.push_back(s);
}

}  // namespace

void LocationParams::Validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) Fail(std::string("location.") + name + " must be > 0, got " + std::to_string(v));
  };
  positive(stay_radius_m, "stay_radius_m");
  positive(min_stay_s, "min_stay_s");
  positive(min_transport_m, "min_transport_m");
  positive(cluster_link_m, "cluster_link_m");
}

LocationAnalysis FindLocationAreas(const Fingerprint& fp, const LocationParams& params) {
  params.Validate();
  LocationAnalysis out;
  const auto& p = fp.profiles;
  const int n = static_cast<int>(p.size());
  if (n < 2) return out;
  auto xy = [&](int i) { return Eigen::Vector2d(p.x_m[static_cast<std::size_t>(i)], p.y_m[static_cast<std::size_t>(i)]); };
  auto t = [&](int i) { return p.t_s[static_cast<std::size_t>(i)]; };

  // Stay points (anchor-based, as in GPS stay-point detection): extend while within the radius.
  std::vector<Stay> stays;
  for (int i = 0; i < n;) {
    int j = i;
    while (j + 1 < n && (xy(j + 1) - xy(i)).norm() <= params.stay_radius_m) ++j;
    if (t(j) - t(i) >= params.min_stay_s) {
      Stay s{i, j, Eigen::Vector2d::Zero()};
      for (int k = i; k <= j; ++k) s.centroid += xy(k);
      s.centroid /= (j - i + 1);
      // Extending the previous stay: the anchor moved but the hand never left (a slow drift).
      if (!stays.empty() && stays.back().last + 1 == i &&
          (stays.back().centroid - s.centroid).norm() < params.min_transport_m) {
        Stay& b = stays.back();
        const int nb = b.last - b.first + 1, ns = j - i + 1;
        b.centroid = (b.centroid * nb + s.centroid * ns) / (nb + ns);
        b.last = j;
      } else {
        stays.push_back(s);
      }
      i = j + 1;
    } else {
      ++i;
    }
  }
  out.stays = static_cast<int>(stays.size());

  if (stays.empty()) {
    // No place where the hand rested (e.g. writing rows): the whole path is one working area.
    LocationArea a;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (int i = 0; i < n; ++i) c += xy(i);
    c /= n;
    std::vector<double> d;
    for (int i = 0; i < n; ++i) d.push_back((xy(i) - c).norm());
    std::sort(d.begin(), d.end());
    a.centre_xy_m = c;
    a.radius_m = d[static_cast<std::size_t>(0.9 * (d.size() - 1))];
    a.dwell_s = t(n - 1) - t(0);
    a.sources = {"path"};
    a.centre_camera_m = fp.frame.origin + c.x() * fp.frame.x_axis + c.y() * fp.frame.y_axis;
    out.areas.push_back(a);
    return out;
  }
  // Transports between consecutive stays far enough apart. A stay anchored at its first sample
  // also holds the first (last) steps of the move away from (towards) it: the transport starts
  // at the last sample still within the stay's core (around its component-wise median, which
  // the approach and departure steps do not pull; radius: the 75th percentile distance plus
  // 5 mm) and stops at the first sample inside the next stay's core.
  auto core = [&](const Stay& st, Eigen::Vector2d* centre) {
    std::vector<double> x, y;
    for (int k = st.first; k <= st.last; ++k) {
      x.push_back(xy(k).x());
      y.push_back(xy(k).y());
    }
    std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
    std::nth_element(y.begin(), y.begin() + y.size() / 2, y.end());
    *centre = Eigen::Vector2d(x[x.size() / 2], y[y.size() / 2]);
    std::vector<double> d;
    for (int k = st.first; k <= st.last; ++k) d.push_back((xy(k) - *centre).norm());
    std::sort(d.begin(), d.end());
    return d[static_cast<std::size_t>(0.75 * (d.size() - 1))] + 0.005;
  };
  const std::vector<Stay> original = stays;
  std::vector<int> transport_from, transport_to;  // stay indices
  for (std::size_t si = 0; si + 1 < stays.size(); ++si) {
    const Stay& a = original[si];
    const Stay& b = original[si + 1];
    if ((b.centroid - a.centroid).norm() < params.min_transport_m) continue;
    Eigen::Vector2d ca, cb;
    const double ra = core(a, &ca), rb = core(b, &cb);
    int start = a.last, stop = b.first;
    while (start > a.first && (xy(start) - ca).norm() > ra) --start;
    while (stop < b.last && (xy(stop) - cb).norm() > rb) ++stop;
    stays[si].last = std::min(stays[si].last, start);
    stays[si + 1].first = std::max(stays[si + 1].first, stop);
    Transport tr;
    tr.start_sample = start;
    tr.end_sample = stop;
    tr.start_xy_m = xy(start);
    tr.end_xy_m = xy(stop);
    for (int k = start; k < stop; ++k) tr.length_m += (xy(k + 1) - xy(k)).norm();
    tr.duration_s = t(stop) - t(start);
    out.transports.push_back(tr);
    transport_from.push_back(static_cast<int>(si));
    transport_to.push_back(static_cast<int>(si + 1));
  }
  for (auto& st : stays) {  // centroids of the trimmed stays
    st.centroid.setZero();
    for (int k = st.first; k <= st.last; ++k) st.centroid += xy(k);
    st.centroid /= (st.last - st.first + 1);
  }

  // Single-linkage clustering of the stays (union-find; stays are few). Each transport end
  // belongs to the area of the stay it leaves or reaches.
  std::vector<int> parent(stays.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t a = 0; a < stays.size(); ++a) {
    for (std::size_t b = a + 1; b < stays.size(); ++b) {
      if ((stays[a].centroid - stays[b].centroid).norm() <= params.cluster_link_m) {
        parent[find(static_cast<int>(a))] = find(static_cast<int>(b));
      }
    }
  }
  std::vector<int> area_of_root(stays.size(), -1), area_of_stay(stays.size(), -1);
  std::vector<std::vector<int>> members;
  for (std::size_t si = 0; si < stays.size(); ++si) {
    const int r = find(static_cast<int>(si));
    if (area_of_root[r] < 0) {
      area_of_root[r] = static_cast<int>(members.size());
      members.emplace_back();
    }
    area_of_stay[si] = area_of_root[r];
    members[area_of_root[r]].push_back(static_cast<int>(si));
  }
  for (std::size_t ai = 0; ai < members.size(); ++ai) {
    LocationArea area;
    std::vector<Eigen::Vector2d> pts;
    for (int si : members[ai]) {
      const Stay& st = stays[si];
      for (int k = st.first; k <= st.last; ++k) pts.push_back(xy(k));
      area.dwell_s += t(st.last) - t(st.first);
      ++area.stays;
    }
    area.sources.push_back("stay");
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const auto& q : pts) centre += q;
    centre /= static_cast<double>(pts.size());
    std::vector<double> d;
    for (const auto& q : pts) d.push_back((q - centre).norm());
    std::sort(d.begin(), d.end());
    area.centre_xy_m = centre;
    area.radius_m = d[static_cast<std::size_t>(0.9 * (d.size() - 1))];
    area.centre_camera_m = fp.frame.origin + centre.x() * fp.frame.x_axis + centre.y() * fp.frame.y_axis;
    out.areas.push_back(area);
  }
  for (std::size_t ti = 0; ti < out.transports.size(); ++ti) {
    Transport& tr = out.transports[ti];
    tr.from_area = area_of_stay[static_cast<std::size_t>(transport_from[ti])];
    tr.to_area = area_of_stay[static_cast<std::size_t>(transport_to[ti])];
    LocationArea& from = out.areas[static_cast<std::size_t>(tr.from_area)];
    LocationArea& to = out.areas[static_cast<std::size_t>(tr.to_area)];
    ++from.transport_starts;
    ++to.transport_ends;
    AddSource(&from, "transport_start");
    AddSource(&to, "transport_end");
  }
  return out;
}

}  // namespace romo::indoor_manip
