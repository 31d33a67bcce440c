#include "trajectories.hpp"

#include <algorithm>
#include <cmath>

#include "romo/core/check.hpp"

namespace romo::sim_manip::internal {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
double Smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// Piecewise motion through keyframes (time, pose) with eased segments: a hand starts and stops
// each stroke smoothly.
struct Keys {
  std::vector<double> t;
  std::vector<HandPose> p;
  void Add(double time, const HandPose& pose) {
    t.push_back(time);
    p.push_back(pose);
  }
  double end() const { return t.empty() ? 0.0 : t.back(); }
  HandPose last() const { return p.back(); }
  HandPose At(double time) const {
    if (time <= t.front()) return p.front();
    if (time >= t.back()) return p.back();
    const auto i = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
    const double s = Smoothstep((time - t[i - 1]) / (t[i] - t[i - 1]));
    const HandPose& a = p[i - 1];
    const HandPose& b = p[i];
    HandPose r;
    r.u_m = a.u_m + s * (b.u_m - a.u_m);
    r.v_m = a.v_m + s * (b.v_m - a.v_m);
    r.h_m = a.h_m + s * (b.h_m - a.h_m);
    r.yaw_rad = a.yaw_rad + s * (b.yaw_rad - a.yaw_rad);
    r.pitch_rad = a.pitch_rad + s * (b.pitch_rad - a.pitch_rad);
    r.roll_rad = a.roll_rad + s * (b.roll_rad - a.roll_rad);
    return r;
  }
};

// Rows of handwriting: a slow left-to-right advance with letter wiggles, word gaps that lift the
// hand, and a fast return to the next row (the sawtooth of Fig. 6.6b).
std::vector<HandPose> Writing(std::mt19937_64& rng, int n, double fps, double scale) {
  const double row_len = Uniform(rng, 0.42, 0.55) * scale;
  const double row_gap = Uniform(rng, 0.11, 0.14) * scale;
  const double row_time = Uniform(rng, 1.2, 1.6);
  const double return_time = Uniform(rng, 0.3, 0.4);
  const double letter_hz = Uniform(rng, 2.5, 3.5);
  const double letter_amp = Uniform(rng, 0.015, 0.028) * scale;
  const double h0 = 0.04;
  const double lift = std::max(0.035, 0.06 * scale);
  const double phase = Uniform(rng, 0.0, 2 * kPi);
  std::vector<HandPose> out(n);
  const double cycle = row_time + return_time;
  // Two word gaps per row at random places.
  std::vector<double> gaps = {Uniform(rng, 0.25, 0.45), Uniform(rng, 0.6, 0.8)};
  for (int k = 0; k < n; ++k) {
    const double t = k / fps;
    const int row = static_cast<int>(t / cycle);
    const double tau = t - row * cycle;
    HandPose& p = out[k];
    p.yaw_rad = 0.1 * std::sin(2 * kPi * 0.3 * t);
    if (tau < row_time) {
      const double s = tau / row_time;
      p.u_m = row_len * s;
      p.v_m = -row * row_gap + letter_amp * std::sin(2 * kPi * letter_hz * t + phase);
      p.h_m = h0 + 0.004 * row;
      for (double g : gaps) p.h_m += lift * 0.7 * std::exp(-0.5 * std::pow((s - g) / 0.03, 2));
    } else {
      const double s = Smoothstep((tau - row_time) / return_time);
      p.u_m = row_len * (1.0 - s);
      p.v_m = -(row + s) * row_gap + letter_amp * std::sin(2 * kPi * letter_hz * t + phase) * (1 - s);
      p.h_m = h0 + 0.004 * row + lift * std::sin(kPi * s);
    }
  }
  // Start exactly at the origin so the camera looks at the first hand position.
  const double u0 = out[0].u_m, v0 = out[0].v_m;
  for (auto& p : out) {
    p.u_m -= u0;
    p.v_m -= v0;
  }
  return out;
}

std::vector<HandPose> Sample(const Keys& keys, int n, double fps) {
  std::vector<HandPose> out(n);
  for (int k = 0; k < n; ++k) out[k] = keys.At(k / fps);
  return out;
}

// Arbitrary strokes and scrubbing circles close to the board (Fig. 6.6c).
std::vector<HandPose> Erasing(std::mt19937_64& rng, int n, double fps) {
  Keys keys;
  const double duration = n / fps + 1.0;
  HandPose p;
  p.h_m = 0.035;
  keys.Add(0.0, p);
  while (keys.end() < duration) {
    HandPose q = keys.last();
    if (Uniform(rng, 0, 1) < 0.35) {  // a scrubbing circle
      const double radius = Uniform(rng, 0.04, 0.09);
      const double step_t = Uniform(rng, 0.08, 0.12);
      const double a0 = Uniform(rng, 0, 2 * kPi);
      for (int i = 1; i <= 8; ++i) {
        HandPose c = q;
        c.u_m = q.u_m + radius * (std::cos(a0 + i * kPi / 4) - std::cos(a0));
        c.v_m = q.v_m + radius * (std::sin(a0 + i * kPi / 4) - std::sin(a0));
        c.h_m = 0.035 + Uniform(rng, -0.004, 0.004);
        keys.Add(keys.end() + step_t, c);
      }
    } else {  // a straight stroke to a random spot of the erased area
      q.u_m = Uniform(rng, -0.05, 0.45);
      q.v_m = Uniform(rng, -0.3, 0.05);
      q.h_m = 0.035 + Uniform(rng, -0.005, 0.005);
      q.yaw_rad = Uniform(rng, -0.15, 0.15);
      keys.Add(keys.end() + Uniform(rng, 0.25, 0.6), q);
    }
  }
  return Sample(keys, n, fps);
}

// Back-and-forth wrist twists about the screw axis; the hand sinks as the screw goes in.
std::vector<HandPose> Tightening(std::mt19937_64& rng, int n, double fps) {
  const double amp = Uniform(rng, 0.6, 0.9);
  const double hz = Uniform(rng, 0.7, 1.1);
  const double arm = Uniform(rng, 0.015, 0.025);  // centroid off the screw axis
  const double sink = Uniform(rng, 0.015, 0.03);
  const double phase = Uniform(rng, 0, 2 * kPi);
  std::vector<HandPose> out(n);
  const double T = n / fps;
  for (int k = 0; k < n; ++k) {
    const double t = k / fps;
    HandPose& p = out[k];
    p.yaw_rad = amp * (std::sin(2 * kPi * hz * t + phase) - std::sin(phase));
    p.u_m = arm * (std::cos(p.yaw_rad) - 1.0);
    p.v_m = arm * std::sin(p.yaw_rad) * 0.5;
    p.h_m = 0.10 - sink * t / T + 0.004 * std::sin(4 * kPi * hz * t);
  }
  return out;
}

// Sudden down-and-up strokes at irregular intervals around one spot, zigzagging a little.
std::vector<HandPose> Poking(std::mt19937_64& rng, int n, double fps) {
  Keys keys;
  const double duration = n / fps + 1.0;
  HandPose up;
  up.h_m = 0.13;
  keys.Add(0.0, up);
  keys.Add(Uniform(rng, 0.1, 0.3), up);
  while (keys.end() < duration) {
    HandPose down = keys.last();
    down.u_m = Uniform(rng, -0.02, 0.02);
    down.v_m = Uniform(rng, -0.02, 0.02);
    down.h_m = Uniform(rng, 0.045, 0.06);
    down.pitch_rad = Uniform(rng, -0.1, 0.1);
    keys.Add(keys.end() + Uniform(rng, 0.1, 0.14), down);
    keys.Add(keys.end() + Uniform(rng, 0.03, 0.08), down);
    HandPose back = down;
    back.h_m = Uniform(rng, 0.11, 0.15);
    back.u_m += Uniform(rng, -0.01, 0.01);
    keys.Add(keys.end() + Uniform(rng, 0.15, 0.25), back);
    keys.Add(keys.end() + Uniform(rng, 0.05, 0.5), back);  // irregular pauses
  }
  return Sample(keys, n, fps);
}

// Hammer blows: a slow arc up and back, a fast strike down (repetitive spikes).
std::vector<HandPose> Hitting(std::mt19937_64& rng, int n, double fps) {
  Keys keys;
  const double duration = n / fps + 1.0;
  HandPose rest;
  rest.h_m = 0.05;
  keys.Add(0.0, rest);
  while (keys.end() < duration) {
    HandPose top = rest;
    top.h_m = Uniform(rng, 0.24, 0.30);
    top.v_m = -0.25 * (top.h_m - rest.h_m);
    top.u_m = Uniform(rng, -0.01, 0.01);
    top.pitch_rad = Uniform(rng, 0.3, 0.5);
    keys.Add(keys.end() + Uniform(rng, 0.45, 0.6), top);
    keys.Add(keys.end() + Uniform(rng, 0.05, 0.1), top);
    HandPose strike = rest;
    strike.u_m = Uniform(rng, -0.01, 0.01);
    keys.Add(keys.end() + Uniform(rng, 0.08, 0.1), strike);
    keys.Add(keys.end() + Uniform(rng, 0.08, 0.2), strike);
  }
  return Sample(keys, n, fps);
}

// Pulling a nail with the claw: slow, regular rocking of the hammer handle.
std::vector<HandPose> Pulling(std::mt19937_64& rng, int n, double fps) {
  const double period = Uniform(rng, 1.4, 2.0);
  const double amp_h = Uniform(rng, 0.03, 0.045);
  const double amp_v = Uniform(rng, 0.04, 0.06);
  std::vector<HandPose> out(n);
  for (int k = 0; k < n; ++k) {
    const double t = k / fps;
    const double w = 2 * kPi * t / period;
    HandPose& p = out[k];
    p.h_m = 0.10 + amp_h * std::sin(w);
    p.v_m = amp_v * (1.0 - std::cos(w));
    p.u_m = 0.005 * std::sin(0.5 * w);
    p.pitch_rad = 0.3 * std::sin(w);
  }
  return out;
}

// Chopping: looping knife strokes (oscillating y and height) at spots that wander along x.
std::vector<HandPose> Chopping(std::mt19937_64& rng, int n, double fps) {
  const double hz = Uniform(rng, 1.6, 2.4);
  const double amp_h = Uniform(rng, 0.03, 0.04);
  const double amp_v = Uniform(rng, 0.025, 0.035);
  Keys spots;
  HandPose s;
  spots.Add(0.0, s);
  while (spots.end() < n / fps + 1.0) {
    s.u_m += Uniform(rng, -0.04, 0.04);
    spots.Add(spots.end() + Uniform(rng, 0.8, 1.4), s);
  }
  std::vector<HandPose> out(n);
  for (int k = 0; k < n; ++k) {
    const double t = k / fps;
    const double w = 2 * kPi * hz * t;
    HandPose& p = out[k];
    p.u_m = spots.At(t).u_m;
    p.v_m = amp_v * std::sin(w);
    p.h_m = 0.08 + amp_h * std::cos(w);
    p.pitch_rad = 0.15 * std::sin(w);
  }
  return out;
}

// Table to mouth and back; drinking pauses at the lips (first contact), goes higher and tilts the
// glass, pauses again on the way down (the inflections of Fig. 6.3d).
std::vector<HandPose> EatingDrinking(std::mt19937_64& rng, int n, double fps, bool drinking) {
  Keys keys;
  const double duration = n / fps + 1.0;
  HandPose rest;
  rest.h_m = 0.05;
  keys.Add(0.0, rest);
  keys.Add(Uniform(rng, 0.2, 0.5), rest);
  while (keys.end() < duration) {
    HandPose mouth = rest;
    mouth.v_m = Uniform(rng, 0.2, 0.26);
    mouth.u_m = Uniform(rng, -0.02, 0.02);
    if (!drinking) {
      mouth.h_m = Uniform(rng, 0.20, 0.26);
      mouth.pitch_rad = 0.2;
      keys.Add(keys.end() + Uniform(rng, 0.6, 0.8), mouth);
      keys.Add(keys.end() + Uniform(rng, 0.15, 0.35), mouth);
    } else {
      mouth.h_m = Uniform(rng, 0.24, 0.26);
      keys.Add(keys.end() + Uniform(rng, 0.6, 0.75), mouth);
      HandPose contact = mouth;
      contact.h_m += 0.008;
      keys.Add(keys.end() + Uniform(rng, 0.25, 0.4), contact);
      HandPose tilt = contact;
      tilt.h_m = Uniform(rng, 0.31, 0.36);
      tilt.v_m += 0.03;
      tilt.pitch_rad = 0.7;
      keys.Add(keys.end() + Uniform(rng, 0.35, 0.45), tilt);
      keys.Add(keys.end() + Uniform(rng, 0.4, 0.7), tilt);
      keys.Add(keys.end() + Uniform(rng, 0.3, 0.4), contact);
      keys.Add(keys.end() + Uniform(rng, 0.2, 0.3), mouth);
    }
    HandPose back = rest;
    back.u_m = Uniform(rng, -0.03, 0.03);
    back.v_m = Uniform(rng, -0.02, 0.02);
    keys.Add(keys.end() + Uniform(rng, 0.55, 0.7), back);
    HandPose fiddle = back;  // picking food / putting the glass down
    fiddle.u_m += Uniform(rng, -0.02, 0.02);
    keys.Add(keys.end() + Uniform(rng, 0.4, 0.9), fiddle);
  }
  return Sample(keys, n, fps);
}

}  // namespace

bool IsBoardAction(const std::string& action) { return action == "writing" || action == "erasing"; }

std::vector<HandPose> GenerateHandPath(const std::string& action, std::mt19937_64& rng, int n,
                                       double fps) {
  if (action == "writing") return Writing(rng, n, fps, 1.0);
  if (action == "writing_pen") return Writing(rng, n, fps, 0.32);
  if (action == "erasing") return Erasing(rng, n, fps);
  if (action == "tightening") return Tightening(rng, n, fps);
  if (action == "poking") return Poking(rng, n, fps);
  if (action == "hitting") return Hitting(rng, n, fps);
  if (action == "pulling") return Pulling(rng, n, fps);
  if (action == "chopping") return Chopping(rng, n, fps);
  if (action == "eating") return EatingDrinking(rng, n, fps, false);
  if (action == "drinking") return EatingDrinking(rng, n, fps, true);
  Fail("sim-manip: unknown action '" + action + "'");
}

}  // namespace romo::sim_manip::internal
