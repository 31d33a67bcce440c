#include "romo/sim_manip/manip_eval.hpp"

#include <algorithm>
#include <cstdio>

#include "romo/core/check.hpp"
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

}  // namespace romo::sim_manip
