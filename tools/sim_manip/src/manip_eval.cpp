#include "romo/sim_manip/manip_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"
#include "romo/core/json.hpp"
#include "romo/indoor_manip/manip_session.hpp"

namespace romo::sim_manip {
namespace {

class SceneSource : public drivers::FrameSource {
 public:
  explicit SceneSource(const SimManipScene& scene) : scene_(scene) {}
  std::optional<drivers::FrameSet> Next() override {
    if (next_ >= scene_.frame_count()) return std::nullopt;
    drivers::FrameSet set;
    set.rgbd = scene_.Render(next_++);
    set.stamp_ns = set.rgbd->stamp_ns;
    return set;
  }
  const drivers::Calibration* calibration() const override { return &scene_.calibration(); }

 private:
  const SimManipScene& scene_;
  int next_ = 0;
};

int Index(const std::vector<std::string>& labels, const std::string& name) {
  const auto it = std::find(labels.begin(), labels.end(), name);
  if (it == labels.end()) Fail("confusion matrix: unknown label '" + name + "'");
  return static_cast<int>(it - labels.begin());
}

}  // namespace

indoor_manip::ManipResult AnalyzeSimManip(const SimManipOptions& options,
                                          const indoor_manip::ManipParams& params) {
  const SimManipScene scene(options);
  SceneSource source(scene);
  indoor_manip::SessionOptions session;
  // The truth seed may fall into a depth hole: take the nearest pixel with depth (the hand is
  // larger than the search window).
  const drivers::RgbdFrame first = scene.Render(0);
  const int w = first.depth.width;
  cv::Point seed(scene.truth().seed_u_px, scene.truth().seed_v_px);
  for (int r = 0; r <= 4; ++r) {
    bool found = false;
    for (int dv = -r; dv <= r && !found; ++dv) {
      for (int du = -r; du <= r && !found; ++du) {
        const int u = seed.x + du, v = seed.y + dv;
        if (u < 0 || v < 0 || u >= w || v >= first.depth.height) continue;
        if (reinterpret_cast<const std::uint16_t*>(first.depth.row(v))[u] != 0) {
          seed = cv::Point(u, v);
          found = true;
        }
      }
    }
    if (found) break;
  }
  session.hand_seed = seed;
  session.params = params;
  const auto k = indoor_manip::IntrinsicsFromSource(source);
  ROMO_DEMAND(k.has_value());
  return indoor_manip::AnalyzeSource(source, *k, session,
                                     "sim-manip://" + options.action + "?seed=" + std::to_string(options.seed));
}

ConfusionMatrix::ConfusionMatrix() : labels(indoor_manip::ActionNames()) {
  labels.push_back("error");
  counts.assign(labels.size(), std::vector<int>(labels.size(), 0));
}

void ConfusionMatrix::Add(const std::string& truth, const std::string& predicted) {
  counts[Index(labels, truth)][Index(labels, predicted)]++;
}

int ConfusionMatrix::Total() const {
  int n = 0;
  for (const auto& row : counts) for (int c : row) n += c;
  return n;
}

double ConfusionMatrix::Accuracy() const {
  int ok = 0;
  for (std::size_t i = 0; i < counts.size(); ++i) ok += counts[i][i];
  const int n = Total();
  return n > 0 ? static_cast<double>(ok) / n : 0.0;
}

int ConfusionMatrix::PairConfusions(const std::string& action) const {
  const int a = Index(labels, action);
  const int b = Index(labels, indoor_manip::ActionPartner(action));
  return counts[a][b] + counts[b][a];
}

std::string ConfusionMatrix::ToText() const {
  std::string out = "truth \\ predicted";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%-12s", "");
  out = buf;
  for (const auto& l : labels) {
    std::snprintf(buf, sizeof(buf), " %6.6s", l.c_str());
    out += buf;
  }
  out += "\n";
  for (std::size_t i = 0; i + 1 < labels.size(); ++i) {
    std::snprintf(buf, sizeof(buf), "%-12s", labels[i].c_str());
    out += buf;
    for (int c : counts[i]) {
      std::snprintf(buf, sizeof(buf), " %6d", c);
      out += buf;
    }
    out += "\n";
  }
  return out;
}

std::string ConfusionMatrix::ToJson() const {
  std::ostringstream s;
  s << "{\n  \"labels\": [";
  for (std::size_t i = 0; i < labels.size(); ++i) s << (i ? ", " : "") << "\"" << JsonEscape(labels[i]) << "\"";
  s << "],\n  \"counts\": [";
  for (std::size_t i = 0; i + 1 < labels.size(); ++i) {  // the "error" row is never a truth
    s << (i ? ",\n    " : "\n    ") << "[";
    for (std::size_t j = 0; j < labels.size(); ++j) s << (j ? ", " : "") << counts[i][j];
    s << "]";
  }
  char acc[32];
  std::snprintf(acc, sizeof(acc), "%.4f", Accuracy());
  s << "],\n  \"total\": " << Total() << ",\n  \"accuracy\": " << acc << ",\n  \"per_action\": {";
  for (std::size_t i = 0; i + 1 < labels.size(); ++i) {
    int runs = 0, predicted = 0;
    for (std::size_t j = 0; j < labels.size(); ++j) runs += counts[i][j];
    for (std::size_t t = 0; t + 1 < labels.size(); ++t) predicted += counts[t][i];
    char buf[96];
    std::snprintf(buf, sizeof(buf), "\"correct\": %d, \"runs\": %d, \"recall\": %.4f, \"precision\": %.4f",
                  counts[i][i], runs, runs ? double(counts[i][i]) / runs : 0.0,
                  predicted ? double(counts[i][i]) / predicted : 0.0);
    s << (i ? ",\n    " : "\n    ") << "\"" << JsonEscape(labels[i]) << "\": {" << buf << "}";
  }
  s << "},\n  \"pairs\": [";
  const auto& names = indoor_manip::ActionNames();
  for (std::size_t i = 0; i + 1 < names.size(); i += 2) {
    s << (i ? ", " : "") << "{\"a\": \"" << names[i] << "\", \"b\": \"" << indoor_manip::ActionPartner(names[i])
      << "\", \"confusions\": " << PairConfusions(names[i]) << "}";
  }
  s << "]\n}\n";
  return s.str();
}

void WriteConfusionPng(const ConfusionMatrix& m, const std::string& path, const std::string& title) {
  const int n_rows = static_cast<int>(m.labels.size()) - 1;  // truths
  const int n_cols = static_cast<int>(m.labels.size());      // predictions incl. "error"
  constexpr int kCell = 56, kLeft = 120, kTop = 130;
  cv::Mat img(kTop + n_rows * kCell + 40, kLeft + n_cols * kCell + 20, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, title, {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "predicted ->", {kLeft, 44}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  for (int j = 0; j < n_cols; ++j) {  // column names written upwards
    cv::Mat text(kCell, 80, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(text, m.labels[j], {2, kCell / 2 + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cv::Mat up;
    cv::rotate(text, up, cv::ROTATE_90_COUNTERCLOCKWISE);
    up.copyTo(img(cv::Rect(kLeft + j * kCell, kTop - 80, kCell, 80)));
  }
  for (int i = 0; i < n_rows; ++i) {
    int runs = 0;
    for (int j = 0; j < n_cols; ++j) runs += m.counts[i][j];
    cv::putText(img, m.labels[i], {6, kTop + i * kCell + kCell / 2 + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    for (int j = 0; j < n_cols; ++j) {
      const int c = m.counts[i][j];
      const double f = runs > 0 ? static_cast<double>(c) / runs : 0.0;
      // Diagonal cells shade green, confusions red; intensity = share of the row.
      const cv::Scalar colour = i == j ? cv::Scalar(255 - 155 * f, 255 - 40 * f, 255 - 155 * f)
                                       : cv::Scalar(255 - 200 * f, 255 - 200 * f, 255);
      const cv::Rect cell(kLeft + j * kCell, kTop + i * kCell, kCell, kCell);
      cv::rectangle(img, cell, colour, cv::FILLED);
      cv::rectangle(img, cell, cv::Scalar(180, 180, 180), 1);
      if (c > 0) {
        cv::putText(img, std::to_string(c), {cell.x + kCell / 2 - 9, cell.y + kCell / 2 + 6},
                    cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      }
    }
  }
  char acc[64];
  std::snprintf(acc, sizeof(acc), "accuracy %.3f over %d runs", m.Accuracy(), m.Total());
  cv::putText(img, acc, {10, img.rows - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  if (!cv::imwrite(path, img)) Fail("cannot write confusion matrix picture '" + path + "'");
}

}  // namespace romo::sim_manip
