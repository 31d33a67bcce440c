#include "romo/indoor_manip/action_label.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

const std::vector<std::string>& ActionNames() {
  static const std::vector<std::string> kNames = {
      "writing", "erasing", "tightening", "poking", "hitting",
      "pulling", "chopping", "writing_pen", "eating", "drinking"};
  return kNames;
}

std::string ActionPartner(const std::string& action) {
  const auto& names = ActionNames();
  const auto it = std::find(names.begin(), names.end(), action);
  if (it == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    Fail("unknown action '" + action + "' (known: " + known + ")");
  }
  const auto i = static_cast<std::size_t>(it - names.begin());
  return names[i ^ 1u];  // pairs are stored next to each other
}

std::vector<std::pair<std::string, double>> ActionFeatures::Named() const {
  return {{"duration_s", duration_s},
          {"x_range_m", x_range_m},
          {"y_range_m", y_range_m},
          {"r_range_m", r_range_m},
          {"r_median_m", r_median_m},
          {"periodicity_x", periodicity_x},
          {"periodicity_y", periodicity_y},
          {"periodicity_r", periodicity_r},
          {"period_r_s", period_r_s},
          {"sawtooth", sawtooth},
          {"spike_rate_hz", spike_rate_hz},
          {"peak_height_m", peak_height_m},
          {"descent_speed_mps", descent_speed_mps},
          {"peak_inflection_fraction", peak_inflection_fraction},
          {"rotation_spread_z_deg", rotation_spread_z_deg},
          {"rotation_spread_xy_deg", rotation_spread_xy_deg}};
}

namespace {

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

double Span(const std::vector<double>& v) { return Percentile(v, 0.95) - Percentile(v, 0.05); }

// Moving average over an odd window (edges use what is there).
std::vector<double> Smooth(const std::vector<double>& v, int half) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::size_t a = i >= static_cast<std::size_t>(half) ? i - half : 0;
    const std::size_t b = std::min(v.size() - 1, i + half);
    out[i] = std::accumulate(v.begin() + a, v.begin() + b + 1, 0.0) / (b - a + 1);
  }
  return out;
}

// Highest local maximum of the normalised autocorrelation of the linearly detrended signal over
// lags 0.3 s .. half the duration: near 1 for a periodic profile, near 0 for a random one.
double Periodicity(const std::vector<double>& v, double dt, double* period_s) {
  const std::size_t n = v.size();
  *period_s = 0.0;
  if (n < 8) return 0.0;
  const double tm = (n - 1) / 2.0;
  double sxy = 0.0, sxx = 0.0, mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (i - tm) * (v[i] - mean);
    sxx += (i - tm) * (i - tm);
  }
  const double slope = sxy / sxx;
  std::vector<double> d(n);
  double var = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    d[i] = v[i] - mean - slope * (i - tm);
    var += d[i] * d[i];
  }
  if (var < 1e-12) return 0.0;
  const std::size_t lag0 = std::max<std::size_t>(2, static_cast<std::size_t>(0.3 / dt));
  const std::size_t lag1 = n / 2;
  std::vector<double> ac(lag1 + 2, 0.0);
  for (std::size_t lag = lag0 - 1; lag <= lag1 + 1 && lag < n; ++lag) {
    double s = 0.0;
    for (std::size_t i = 0; i + lag < n; ++i) s += d[i] * d[i + lag];
    // Unbiased by overlap so long lags are not penalised for having fewer products.
    ac[std::min(lag, lag1 + 1)] = s / var * (static_cast<double>(n) / (n - lag));
  }
  double best = 0.0;
  for (std::size_t lag = lag0; lag <= lag1; ++lag) {
    if (ac[lag] > ac[lag - 1] && ac[lag] >= ac[lag + 1] && ac[lag] > best) {
      best = ac[lag];
      *period_s = lag * dt;
    }
  }
  return std::clamp(best, 0.0, 1.0);
}

double Skewness(const std::vector<double>& v) {
  if (v.size() < 3) return 0.0;
  const double n = static_cast<double>(v.size());
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  double m2 = 0.0, m3 = 0.0;
  for (double x : v) {
    m2 += (x - mean) * (x - mean);
    m3 += (x - mean) * (x - mean) * (x - mean);
  }
  m2 /= n;
  m3 /= n;
  return m2 > 1e-15 ? m3 / std::pow(m2, 1.5) : 0.0;
}

struct Peak {
  std::size_t index;
  double prominence;
};

// Local maxima whose prominence (height above the higher of the two minima towards the nearest
// higher samples on either side) reaches min_prominence.
std::vector<Peak> FindPeaks(const std::vector<double>& v, double min_prominence) {
  std::vector<Peak> peaks;
  for (std::size_t i = 1; i + 1 < v.size(); ++i) {
    if (!(v[i] > v[i - 1] && v[i] >= v[i + 1])) continue;
    double left_min = v[i], right_min = v[i];
    for (std::size_t j = i; j-- > 0;) {
      if (v[j] > v[i]) break;
      left_min = std::min(left_min, v[j]);
    }
    for (std::size_t j = i + 1; j < v.size(); ++j) {
      if (v[j] > v[i]) break;
      right_min = std::min(right_min, v[j]);
    }
    const double prom = v[i] - std::max(left_min, right_min);
    if (prom >= min_prominence) peaks.push_back({i, prom});
  }
  return peaks;
}

// A flank has an inflection when its speed falls below 35% of its peak speed and picks up again:
// the pause of a glass at the lips on the way up or down.
bool FlankHasPause(const std::vector<double>& speed, std::size_t a, std::size_t b) {
  if (b <= a + 4) return false;
  const double vmax = *std::max_element(speed.begin() + a, speed.begin() + b);
  if (vmax <= 0.0) return false;
  int state = 0;  // 0 before fast, 1 fast, 2 paused after fast
  for (std::size_t i = a; i < b; ++i) {
    const double s = speed[i] / vmax;
    if (state == 0 && s > 0.6) state = 1;
    else if (state == 1 && s < 0.35) state = 2;
    else if (state == 2 && s > 0.6) return true;
  }
  return false;
}

}  // namespace

ActionFeatures ComputeActionFeatures(const MotionProfiles& p,
                                     const std::vector<Eigen::Vector3d>& rotation_steps_rad) {
  ActionFeatures f;
  const std::size_t n = p.size();
  if (n < 2) return f;
  f.duration_s = p.t_s.back() - p.t_s.front();
  const double dt = f.duration_s / (n - 1);
  f.x_range_m = Span(p.x_m);
  f.y_range_m = Span(p.y_m);
  f.r_range_m = Span(p.r_m);
  f.r_median_m = Percentile(p.r_m, 0.5);
  double unused = 0.0;
  f.periodicity_x = Periodicity(p.x_m, dt, &unused);
  f.periodicity_y = Periodicity(p.y_m, dt, &unused);
  f.periodicity_r = Periodicity(p.r_m, dt, &f.period_r_s);

  // Sawtooth: slow constant advance and fast returns give a strongly skewed velocity along the
  // row axis (x for western rows, y for vertical ones): the larger |skewness| of the two.
  for (const auto* axis : {&p.x_m, &p.y_m}) {
    const auto sm = Smooth(*axis, 2);
    std::vector<double> vel(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i) vel[i] = (sm[i + 1] - sm[i]) / dt;
    f.sawtooth = std::max(f.sawtooth, std::abs(Skewness(vel)));
  }

  const auto r_s = Smooth(p.r_m, 1);
  const double min_prom = 0.03;  // 3 cm: above the hand's depth noise, below any real stroke
  const auto peaks = FindPeaks(r_s, min_prom);
  f.spike_rate_hz = f.duration_s > 0 ? peaks.size() / f.duration_s : 0.0;
  std::vector<double> heights;
  for (const auto& pk : peaks) heights.push_back(r_s[pk.index]);
  f.peak_height_m = Percentile(heights, 0.5);
  std::vector<double> down, speed(n, 0.0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double v = (r_s[i + 1] - r_s[i]) / dt;
    down.push_back(std::max(0.0, -v));
    speed[i] = std::abs(v);
  }
  f.descent_speed_mps = Percentile(down, 0.95);
  // Inflections on the flanks of high peaks (those reaching 60% of the highest).
  int high = 0, paused = 0;
  const double r_hi = heights.empty() ? 0.0 : *std::max_element(heights.begin(), heights.end());
  for (const auto& pk : peaks) {
    if (r_s[pk.index] < 0.6 * r_hi || pk.prominence < 0.08) continue;
    ++high;
    const double base = r_s[pk.index] - pk.prominence;
    std::size_t a = pk.index, b = pk.index;
    while (a > 0 && r_s[a - 1] < r_s[a] + 1e-4 && r_s[a - 1] > base + 0.1 * pk.prominence) --a;
    while (b + 1 < n && r_s[b + 1] < r_s[b] + 1e-4 && r_s[b + 1] > base + 0.1 * pk.prominence) ++b;
    if (FlankHasPause(speed, a, pk.index) || FlankHasPause(speed, pk.index, b)) ++paused;
  }
  f.peak_inflection_fraction = high > 0 ? static_cast<double>(paused) / high : 0.0;

  // Rotation spread: standard deviation of the per-step angle per axis (degrees per frame); the
  // spread of the per-step histogram, unaffected by the drift of the cumulative angle.
  if (!rotation_steps_rad.empty()) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
    for (const auto& s : rotation_steps_rad) {
      sum += s;
      sq += s.cwiseProduct(s);
    }
    const double m = static_cast<double>(rotation_steps_rad.size());
    const Eigen::Vector3d var = (sq / m - (sum / m).cwiseProduct(sum / m)).cwiseMax(0.0);
    const Eigen::Vector3d sd = var.cwiseSqrt() * 180.0 / M_PI;
    f.rotation_spread_z_deg = sd.z();
    f.rotation_spread_xy_deg = std::max(sd.x(), sd.y());
  }
  return f;
}

void ActionThresholds::Validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0)) Fail(std::string("thresholds.") + name + " must be > 0, got " + std::to_string(v));
  };
  positive(tightening_rotation_deg, "tightening_rotation_deg");
  positive(tightening_max_xy_range_m, "tightening_max_xy_range_m");
  positive(tightening_max_spike_rate_hz, "tightening_max_spike_rate_hz");
  positive(high_peak_m, "high_peak_m");
  positive(hitting_descent_mps, "hitting_descent_mps");
  positive(drinking_peak_m, "drinking_peak_m");
  positive(drinking_inflection_fraction, "drinking_inflection_fraction");
  positive(sawtooth, "sawtooth");
  positive(sawtooth_periodicity, "sawtooth_periodicity");
  positive(board_row_length_m, "board_row_length_m");
  positive(stroke_spike_rate_hz, "stroke_spike_rate_hz");
  positive(regular_periodicity, "regular_periodicity");
  positive(pulling_min_r_range_m, "pulling_min_r_range_m");
}

namespace {
std::string Cmp(const char* name, double value, const char* op, double threshold) {
  std::ostringstream s;
  s.precision(3);
  s << name << " " << value << " " << op << " " << threshold;
  return s.str();
}
}  // namespace

ActionDecision ClassifyAction(const ActionFeatures& f, const ActionThresholds& t) {
  ActionDecision d;
  auto& why = d.reasons;
  const double xy = std::max(f.x_range_m, f.y_range_m);
  // 1. Tightening: wrist turns about the plane normal with only short translations (Table 6.2).
  if (f.rotation_spread_z_deg > t.tightening_rotation_deg && xy < t.tightening_max_xy_range_m &&
      f.spike_rate_hz < t.tightening_max_spike_rate_hz) {
    why.push_back(Cmp("rotation_spread_z_deg", f.rotation_spread_z_deg, ">", t.tightening_rotation_deg));
    why.push_back(Cmp("xy_range_m", xy, "<", t.tightening_max_xy_range_m));
    why.push_back(Cmp("spike_rate_hz", f.spike_rate_hz, "<", t.tightening_max_spike_rate_hz));
    d.label = "tightening";
    return d;
  }
  // 2. Actions that lift the hand far from the plane: hammer blows, fork and glass to the mouth.
  if (f.peak_height_m > t.high_peak_m) {
    why.push_back(Cmp("peak_height_m", f.peak_height_m, ">", t.high_peak_m));
    if (f.descent_speed_mps > t.hitting_descent_mps) {
      why.push_back(Cmp("descent_speed_mps", f.descent_speed_mps, ">", t.hitting_descent_mps));
      d.label = "hitting";
      return d;
    }
    why.push_back(Cmp("descent_speed_mps", f.descent_speed_mps, "<=", t.hitting_descent_mps));
    const bool high = f.peak_height_m > t.drinking_peak_m;
    const bool inflected = f.peak_inflection_fraction >= t.drinking_inflection_fraction;
    why.push_back(Cmp("peak_height_m", f.peak_height_m, high ? ">" : "<=", t.drinking_peak_m));
    why.push_back(Cmp("peak_inflection_fraction", f.peak_inflection_fraction,
                      inflected ? ">=" : "<", t.drinking_inflection_fraction));
    d.label = (high || inflected) ? "drinking" : "eating";
    return d;
  }
  why.push_back(Cmp("peak_height_m", f.peak_height_m, "<=", t.high_peak_m));
  // 3. Writing: a periodic sawtooth along the rows; its scale tells board from pen.
  const double row_period = std::max(f.periodicity_x, f.periodicity_y);
  if (f.sawtooth > t.sawtooth && row_period > t.sawtooth_periodicity) {
    why.push_back(Cmp("sawtooth", f.sawtooth, ">", t.sawtooth));
    why.push_back(Cmp("row_periodicity", row_period, ">", t.sawtooth_periodicity));
    const bool board = xy > t.board_row_length_m;
    why.push_back(Cmp("row_length_m", xy, board ? ">" : "<=", t.board_row_length_m));
    d.label = board ? "writing" : "writing_pen";
    return d;
  }
  why.push_back(Cmp("sawtooth", f.sawtooth, "<=", t.sawtooth) + " or " +
                Cmp("row_periodicity", row_period, "<=", t.sawtooth_periodicity));
  // 4. Strokes towards the plane: irregular ones poke, regular ones chop.
  const bool regular = f.periodicity_r > t.regular_periodicity;
  if (f.spike_rate_hz > t.stroke_spike_rate_hz) {
    why.push_back(Cmp("spike_rate_hz", f.spike_rate_hz, ">", t.stroke_spike_rate_hz));
    why.push_back(Cmp("periodicity_r", f.periodicity_r, regular ? ">" : "<=", t.regular_periodicity));
    d.label = regular ? "chopping" : "poking";
    return d;
  }
  why.push_back(Cmp("spike_rate_hz", f.spike_rate_hz, "<=", t.stroke_spike_rate_hz));
  // 5. Pulling: a slow, regular rocking of the distance to the plane; erasing: arbitrary strokes
  // close to the plane.
  const bool rocking = regular && f.r_range_m > t.pulling_min_r_range_m;
  why.push_back(Cmp("periodicity_r", f.periodicity_r, regular ? ">" : "<=", t.regular_periodicity));
  why.push_back(Cmp("r_range_m", f.r_range_m, f.r_range_m > t.pulling_min_r_range_m ? ">" : "<=",
                    t.pulling_min_r_range_m));
  d.label = rocking ? "pulling" : "erasing";
  return d;
}

}  // namespace romo::indoor_manip
