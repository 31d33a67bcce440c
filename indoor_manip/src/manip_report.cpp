// Plots (OpenCV drawing) and the JSON label of a manipulation analysis.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "romo/core/json.hpp"
#include "romo/core/check.hpp"
#include "romo/indoor_manip/manip_analyzer.hpp"

namespace romo::indoor_manip {
namespace {

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrey(200, 200, 200);
// BGR: x red, y green, r blue as in Fig. 4.3h.
const cv::Scalar kRed(40, 40, 220), kGreen(40, 170, 40), kBlue(220, 90, 30);

struct Axes {
  cv::Rect area;
  double x0, x1, y0, y1;
  cv::Point Map(double x, double y) const {
    const double fx = (x - x0) / std::max(1e-12, x1 - x0);
    const double fy = (y - y0) / std::max(1e-12, y1 - y0);
    return {area.x + static_cast<int>(fx * area.width),
            area.y + area.height - static_cast<int>(fy * area.height)};
  }
};

std::string Fmt(double v, int precision = 2) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", precision, v);
  return buf;
}

void DrawFrame(cv::Mat& img, const Axes& ax, const std::string& title, const std::string& xlabel,
               const std::string& ylabel) {
  cv::rectangle(img, ax.area, kBlack, 1);
  cv::putText(img, title, {ax.area.x, ax.area.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.5, kBlack, 1);
  cv::putText(img, xlabel + " [" + Fmt(ax.x0) + ", " + Fmt(ax.x1) + "]",
              {ax.area.x, ax.area.y + ax.area.height + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.4, kBlack, 1);
  cv::putText(img, ylabel + " " + Fmt(ax.y1, 3), {ax.area.x + 4, ax.area.y + 14},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, kBlack, 1);
  cv::putText(img, Fmt(ax.y0, 3), {ax.area.x + 4, ax.area.y + ax.area.height - 4},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, kBlack, 1);
}

void DrawSeries(cv::Mat& img, const Axes& ax, const std::vector<double>& x,
                const std::vector<double>& y, const cv::Scalar& colour) {
  for (std::size_t i = 1; i < x.size(); ++i) {
    cv::line(img, ax.Map(x[i - 1], y[i - 1]), ax.Map(x[i], y[i]), colour, 2, cv::LINE_AA);
  }
}

std::pair<double, double> Range(const std::vector<double>& v) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const double pad = std::max(1e-3, 0.05 * (*hi - *lo));
  return {*lo - pad, *hi + pad};
}

cv::Mat FingerprintPlot(const ManipResult& r) {
  const auto& p = r.fingerprint.profiles;
  cv::Mat img(520, 520, CV_8UC3, kWhite);
  const auto [xa, xb] = Range(p.x_m);
  const auto [ya, yb] = Range(p.y_m);
  // Equal scale on both axes so the pattern keeps its shape.
  const double half = 0.5 * std::max(xb - xa, yb - ya);
  const double xc = 0.5 * (xa + xb), yc = 0.5 * (ya + yb);
  Axes ax{cv::Rect(40, 40, 440, 440), xc - half, xc + half, yc - half, yc + half};
  DrawFrame(img, ax, std::string("fingerprint (") + ToString(r.fingerprint.encapsulation) +
                         "), label " + r.decision.label, "x m", "y m");
  const Eigen::Vector2d e = r.fingerprint.box_extent_m;
  cv::rectangle(img, ax.Map(-e.x() / 2, -e.y() / 2), ax.Map(e.x() / 2, e.y() / 2), kGrey, 1);
  const std::size_t n = p.size();
  for (std::size_t i = 1; i < n; ++i) {
    const double f = static_cast<double>(i) / n;  // dark to light over time
    cv::line(img, ax.Map(p.x_m[i - 1], p.y_m[i - 1]), ax.Map(p.x_m[i], p.y_m[i]),
             cv::Scalar(60 + 150 * f, 30, 150 - 120 * f), 2, cv::LINE_AA);
  }
  // Location areas (green circles, radius to scale) and transport ends (orange start, red stop).
  const double px_per_m = ax.area.width / std::max(1e-9, ax.x1 - ax.x0);
  const auto& loc = r.locations;
  for (std::size_t a = 0; a < loc.areas.size(); ++a) {
    const auto& area = loc.areas[a];
    const cv::Point c = ax.Map(area.centre_xy_m.x(), area.centre_xy_m.y());
    cv::circle(img, c, std::max(4, static_cast<int>(area.radius_m * px_per_m)), kGreen, 2, cv::LINE_AA);
    cv::putText(img, "A" + std::to_string(a), c + cv::Point(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5, kGreen, 2);
  }
  for (const auto& tr : loc.transports) {
    const cv::Point a = ax.Map(tr.start_xy_m.x(), tr.start_xy_m.y());
    const cv::Point b = ax.Map(tr.end_xy_m.x(), tr.end_xy_m.y());
    cv::arrowedLine(img, a, b, cv::Scalar(0, 140, 255), 1, cv::LINE_AA, 0, 0.05);
    cv::circle(img, a, 5, cv::Scalar(0, 140, 255), cv::FILLED);
    cv::circle(img, b, 5, kRed, cv::FILLED);
  }
  return img;
}

cv::Mat ProfilesPlot(const ManipResult& r) {
  const auto& p = r.fingerprint.profiles;
  cv::Mat img(640, 800, CV_8UC3, kWhite);
  const double t1 = p.t_s.empty() ? 1.0 : std::max(1e-3, p.t_s.back());
  const std::vector<std::pair<const std::vector<double>*, cv::Scalar>> rows = {
      {&p.x_m, kRed}, {&p.y_m, kGreen}, {&p.r_m, kBlue}};
  const char* names[3] = {"x(t) m", "y(t) m", "r(t) distance to plane m"};
  for (int i = 0; i < 3; ++i) {
    const auto [lo, hi] = Range(*rows[i].first);
    Axes ax{cv::Rect(60, 30 + i * 205, 720, 165), 0.0, t1, lo, hi};
    DrawFrame(img, ax, names[i], "t s", "");
    DrawSeries(img, ax, p.t_s, *rows[i].first, rows[i].second);
  }
  return img;
}

cv::Mat RotationPlot(const ManipResult& r) {
  cv::Mat img(440, 900, CV_8UC3, kWhite);
  const char* axis_names[3] = {"Hx", "Hy", "Hz"};
  std::vector<double> step[3], cum[3];
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& s : r.rotation_steps_rad) {
    c += s;
    for (int a = 0; a < 3; ++a) {
      step[a].push_back(s[a] * 180.0 / M_PI);
      cum[a].push_back(c[a] * 180.0 / M_PI);
    }
  }
  for (int row = 0; row < 2; ++row) {
    for (int a = 0; a < 3; ++a) {
      const double lim = row == 0 ? 15.0 : 90.0;  // per-step vs cumulative range, degrees
      const AngleHistogram h = MakeHistogram(row == 0 ? step[a] : cum[a], -lim, lim, 30);
      const int peak = std::max(1, *std::max_element(h.counts.begin(), h.counts.end()));
      Axes ax{cv::Rect(30 + a * 290, 40 + row * 210, 260, 150), -lim, lim, 0.0, double(peak)};
      DrawFrame(img, ax, std::string(row == 0 ? "per-step " : "cumulative ") + axis_names[a] + " deg",
                "deg", "n");
      for (std::size_t b = 0; b < h.counts.size(); ++b) {
        const double x0 = h.min_deg + b * h.bin_deg;
        cv::rectangle(img, ax.Map(x0, 0), ax.Map(x0 + h.bin_deg, h.counts[b]), kBlue, cv::FILLED);
      }
    }
  }
  return img;
}

void Write(const std::string& path, const cv::Mat& img) {
  if (!cv::imwrite(path, img)) Fail("cannot write plot '" + path + "'");
}

std::string Num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

}  // namespace

void WriteManipPlots(const ManipResult& result, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) Fail("cannot create output folder '" + dir + "': " + ec.message());
  Write(dir + "/fingerprint.png", FingerprintPlot(result));
  Write(dir + "/profiles.png", ProfilesPlot(result));
  Write(dir + "/rotation.png", RotationPlot(result));
}

std::string ManipResultJson(const ManipResult& r) {
  std::ostringstream s;
  s << "{\n  \"label\": \"" << JsonEscape(r.decision.label) << "\",\n  \"evidence\": {\n";
  for (const auto& [name, value] : r.features.Named()) s << "    \"" << name << "\": " << Num(value) << ",\n";
  s << "    \"location_areas\": [";
  for (std::size_t i = 0; i < r.locations.areas.size(); ++i) {
    const auto& a = r.locations.areas[i];
    s << (i ? ",\n      " : "\n      ") << "{\"id\": " << i << ", \"centre_xy_m\": [" << Num(a.centre_xy_m.x())
      << ", " << Num(a.centre_xy_m.y()) << "], \"centre_camera_m\": [" << Num(a.centre_camera_m.x())
      << ", " << Num(a.centre_camera_m.y()) << ", " << Num(a.centre_camera_m.z())
      << "], \"radius_m\": " << Num(a.radius_m) << ", \"dwell_s\": " << Num(a.dwell_s)
      << ", \"stays\": " << a.stays << ", \"transport_starts\": " << a.transport_starts
      << ", \"transport_ends\": " << a.transport_ends << ", \"sources\": [";
    for (std::size_t k = 0; k < a.sources.size(); ++k) s << (k ? ", " : "") << "\"" << a.sources[k] << "\"";
    s << "]}";
  }
  s << "],\n    \"transports\": [";
  for (std::size_t i = 0; i < r.locations.transports.size(); ++i) {
    const auto& t = r.locations.transports[i];
    s << (i ? ",\n      " : "\n      ") << "{\"from_area\": " << t.from_area << ", \"to_area\": " << t.to_area
      << ", \"start_xy_m\": [" << Num(t.start_xy_m.x()) << ", " << Num(t.start_xy_m.y())
      << "], \"end_xy_m\": [" << Num(t.end_xy_m.x()) << ", " << Num(t.end_xy_m.y())
      << "], \"length_m\": " << Num(t.length_m) << ", \"duration_s\": " << Num(t.duration_s) << "}";
  }
  s << "],\n";
  s << "    \"reasons\": [";
  for (std::size_t i = 0; i < r.decision.reasons.size(); ++i) {
    s << (i ? ", " : "") << "\"" << JsonEscape(r.decision.reasons[i]) << "\"";
  }
  s << "]\n  },\n";
  s << "  \"plane\": {\"normal\": [" << Num(r.plane.normal.x()) << ", " << Num(r.plane.normal.y())
    << ", " << Num(r.plane.normal.z()) << "], \"d_m\": " << Num(r.plane.d_m) << "},\n";
  s << "  \"encapsulation\": {\"kind\": \"" << ToString(r.fingerprint.encapsulation)
    << "\", \"extent_m\": [" << Num(r.fingerprint.box_extent_m.x()) << ", "
    << Num(r.fingerprint.box_extent_m.y()) << "], \"height_m\": " << Num(r.fingerprint.box_height_m)
    << "},\n";
  s << "  \"frames\": " << r.frames << ",\n  \"frames_without_hand\": " << r.frames_without_hand
    << "\n}\n";
  return s.str();
}

}  // namespace romo::indoor_manip
