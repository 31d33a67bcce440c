#include "romo/objects/trajectory_eval.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::objects {
namespace {

constexpr std::size_t kMaxNotes = 10;
// Frame numbers are stored as text floats ("10.0"); equal within this.
constexpr double kFrameTolerance = 1e-6;

}  // namespace

TrajectorySet ReadEthUcy(const std::string& path, bool strict) {
  std::ifstream in(path);
  if (!in) Fail("trajectory file '" + path + "': cannot open");
  TrajectorySet set;
  set.path = path;
  std::string line;
  std::int64_t line_no = 0;
  auto problem = [&](std::int64_t* counter, const std::string& what) {
    const std::string note = path + ":" + std::to_string(line_no) + ": " + what;
    if (strict) Fail("trajectory file " + note);
    ++*counter;
    if (set.notes.size() < kMaxNotes) set.notes.push_back(note);
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;  // blank lines are fine
    std::istringstream fields(line);
    std::string tok[5];
    int count = 0;
    while (count < 5 && fields >> tok[count]) ++count;
    if (count != 4) {
      problem(&set.skipped_malformed,
              "expected 4 fields 'frame ped_id x y', got " + std::to_string(count) + " ('" +
                  line + "')");
      continue;
    }
    double v[4];
    bool parsed = true;
    for (int i = 0; i < 4 && parsed; ++i) {
      // strtod accepts "nan"/"inf", which we report separately from text that is no number.
      char* end = nullptr;
      v[i] = std::strtod(tok[i].c_str(), &end);
      parsed = end != tok[i].c_str() && *end == '\0';
    }
    if (!parsed) {
      problem(&set.skipped_malformed, "not a number in '" + line + "'");
      continue;
    }
    if (!std::isfinite(v[0]) || !std::isfinite(v[2]) || !std::isfinite(v[3]) ||
        !std::isfinite(v[1])) {
      problem(&set.skipped_nonfinite, "non-finite value in '" + line + "'");
      continue;
    }
    if (v[1] != std::floor(v[1])) {
      problem(&set.skipped_malformed, "pedestrian id is not an integer ('" + tok[1] + "')");
      continue;
    }
    // Converting a double beyond long's range is undefined (found by fuzz_eth_ucy: 3.4e39).
    if (std::abs(v[1]) > 1e15) {
      problem(&set.skipped_malformed, "pedestrian id out of range ('" + tok[1] + "')");
      continue;
    }
    set.tracks[static_cast<long>(v[1])].push_back({v[0], Eigen::Vector2d(v[2], v[3])});
  }
  if (in.bad()) Fail("trajectory file '" + path + "': read error");
  // Sort each pedestrian by frame and drop repeated frames (keeping the first row in the file).
  for (auto& [id, samples] : set.tracks) {
    std::stable_sort(samples.begin(), samples.end(),
                     [](const auto& a, const auto& b) { return a.frame < b.frame; });
    std::vector<TrajectorySample> unique;
    unique.reserve(samples.size());
    for (const auto& s : samples) {
      if (!unique.empty() && std::abs(unique.back().frame - s.frame) < kFrameTolerance) {
        // The line is no longer known after sorting: name pedestrian and frame instead.
        const std::string note = path + ": duplicate frame " + std::to_string(s.frame) +
                                 " of pedestrian " + std::to_string(id);
        if (strict) Fail("trajectory file " + note);
        ++set.skipped_duplicate;
        if (set.notes.size() < kMaxNotes) set.notes.push_back(note);
        continue;
      }
      unique.push_back(s);
    }
    samples = std::move(unique);
    if (samples.size() == 1) ++set.pedestrians_seen_once;
    set.rows_used += static_cast<std::int64_t>(samples.size());
  }
  if (set.rows_used == 0) {
    Fail("trajectory file '" + path + "': no valid 'frame ped_id x y' row (" +
         std::to_string(set.skipped_total()) + " rows skipped)");
  }
  return set;
}

void WindowParams::Validate() const {
  auto bad = [](const char* field, double value, const char* expected) {
    std::ostringstream m;
    m << "window " << field << " = " << value << " is invalid (" << expected << ")";
    Fail(m.str());
  };
  if (obs < 2) bad("obs", obs, "need at least 2 observed steps");
  if (pred < 1) bad("pred", pred, "need at least 1 predicted step");
  if (!(frame_step >= 0.0) || !std::isfinite(frame_step)) bad("frame_step", frame_step, "need >= 0");
  if (!(step_s > 0.0) || !std::isfinite(step_s)) bad("step_s", step_s, "need > 0");
}

double InferFrameStep(const TrajectorySet& set) {
  std::map<long long, std::int64_t> histogram;  // step in 1e-6 frame units -> count
  for (const auto& [id, samples] : set.tracks) {
    for (std::size_t i = 1; i < samples.size(); ++i) {
      const double d = samples[i].frame - samples[i - 1].frame;
      ++histogram[std::llround(d / kFrameTolerance)];
    }
  }
  if (histogram.empty()) {
    Fail("trajectory file '" + set.path + "': no pedestrian has two samples, frame step unknown");
  }
  auto best = std::max_element(histogram.begin(), histogram.end(),
                               [](const auto& a, const auto& b) { return a.second < b.second; });
  return static_cast<double>(best->first) * kFrameTolerance;
}

TrajectoryEvalResult EvaluateTrajectories(const TrajectorySet& set, const WindowParams& window,
                                          const PredictorParams& rls) {
  window.Validate();
  PredictorParams rls_params = rls;
  rls_params.kind = PredictorKind::kRls;
  rls_params.Validate();
  PredictorParams cv_params = rls_params;
  cv_params.kind = PredictorKind::kConstantVelocity;

  TrajectoryEvalResult result;
  result.frame_step = window.frame_step > 0.0 ? window.frame_step : InferFrameStep(set);
  const int length = window.obs + window.pred;
  double sums[4] = {0, 0, 0, 0};  // rls ade, rls fde, cv ade, cv fde
  for (const auto& [id, s] : set.tracks) {
    const int n = static_cast<int>(s.size());
    for (int start = 0; start + length <= n; ++start) {
      const double expected_last = s[start].frame + (length - 1) * result.frame_step;
      // Sorted and unique, so the window is gap-free exactly when its span is right.
      if (std::abs(s[start + length - 1].frame - expected_last) > 1e-3 * result.frame_step) {
        continue;
      }
      RlsPathPredictor rls_predictor(rls_params);
      ConstantVelocityPredictor cv_predictor(cv_params);
      for (int k = 0; k < window.obs; ++k) {
        rls_predictor.Update(k * window.step_s, s[start + k].xy_m);
        cv_predictor.Update(k * window.step_s, s[start + k].xy_m);
      }
      const PathPredictor* predictors[2] = {&rls_predictor, &cv_predictor};
      for (int p = 0; p < 2; ++p) {
        const auto path = predictors[p]->Predict(window.pred, window.step_s);
        double sum = 0.0;
        double last = 0.0;
        for (int k = 0; k < window.pred; ++k) {
          last = (path[k].xy_m - s[start + window.obs + k].xy_m).norm();
          sum += last;
        }
        sums[2 * p] += sum / window.pred;
        sums[2 * p + 1] += last;
      }
      ++result.windows;
    }
  }
  if (result.windows == 0) {
    Fail("trajectory file '" + set.path + "': no window of " + std::to_string(length) +
         " consecutive frames (obs " + std::to_string(window.obs) + " + pred " +
         std::to_string(window.pred) + ")");
  }
  const double w = static_cast<double>(result.windows);
  result.romo = {sums[0] / w, sums[1] / w};
  result.cv = {sums[2] / w, sums[3] / w};
  return result;
}

}  // namespace romo::objects
