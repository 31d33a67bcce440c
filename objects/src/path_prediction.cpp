#include "romo/objects/path_prediction.hpp"

#include <cmath>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::objects {
namespace {

// Large enough to make the first observations define the fit (no prior pull), small enough to
// keep P well conditioned in double precision.
constexpr double kInitialP = 1e6;

void CheckObservation(const char* who, bool have_last, double t_last, double t_s,
                      const Eigen::Vector2d& xy_m) {
  if (!std::isfinite(t_s) || !xy_m.allFinite()) {
    std::ostringstream m;
    m << who << ": observation is not finite (t_s=" << t_s << ", x=" << xy_m.x()
      << ", y=" << xy_m.y() << ")";
    Fail(m.str());
  }
  if (have_last && !(t_s > t_last)) {
    std::ostringstream m;
    m << who << ": observation time " << t_s << " s does not increase (last " << t_last << " s)";
    Fail(m.str());
  }
}

}  // namespace

const char* ToString(PredictorKind kind) {
  return kind == PredictorKind::kRls ? "rls" : "cv";
}

PredictorKind ParsePredictorKind(const std::string& text) {
  if (text == "rls") return PredictorKind::kRls;
  if (text == "cv") return PredictorKind::kConstantVelocity;
  Fail("predictor: unknown kind '" + text + "' (expected rls or cv)");
}

void PredictorParams::Validate() const {
  auto bad = [](const char* field, double value, const char* expected) {
    std::ostringstream m;
    m << "PredictorParams." << field << " = " << value << " is invalid (" << expected << ")";
    Fail(m.str());
  };
  if (!(forgetting > 0.0 && forgetting <= 1.0)) bad("forgetting", forgetting, "need 0 < f <= 1");
  if (!(horizon_s >= 0.0) || !std::isfinite(horizon_s)) bad("horizon_s", horizon_s, "need >= 0");
  if (!(step_s >= 0.0) || !std::isfinite(step_s)) bad("step_s", step_s, "need >= 0");
  if (!(min_sigma_m >= 0.0) || !std::isfinite(min_sigma_m)) {
    bad("min_sigma_m", min_sigma_m, "need >= 0");
  }
  if (noise_window < 4) bad("noise_window", noise_window, "need >= 4 positions");
  if (!(noise_correlation_threshold >= -1.0 && noise_correlation_threshold <= 1.0)) {
    bad("noise_correlation_threshold", noise_correlation_threshold, "need -1 <= r <= 1");
  }
}

PathPredictor::PathPredictor(const PredictorParams& params) : params_(params) {
  params_.Validate();
}

std::vector<PredictedPoint> PathPredictor::PredictHorizon() const {
  const double step = params_.step_s > 0.0 ? params_.step_s : mean_step_s();
  if (observations() == 0 || step <= 0.0) return {};
  const int steps = static_cast<int>(std::lround(params_.horizon_s / step));
  return Predict(steps, step);
}

// ---------------------------------------------------------------------------------------------
RlsPathPredictor::RlsPathPredictor(const PredictorParams& params) : PathPredictor(params) {
  P_ = Eigen::Matrix2d::Identity() * kInitialP;
  recent_.reserve(static_cast<std::size_t>(params_.noise_window));
  recent_t_.reserve(static_cast<std::size_t>(params_.noise_window));
}

double RlsPathPredictor::SecondDifferenceCorrelation() const {
  const int m = static_cast<int>(recent_.size());
  if (m < 4) return 0.0;
  // Oldest first: the ring's next slot holds the oldest entry once it is full.
  auto at = [&](int i) -> const Eigen::Vector2d& {
    return recent_[static_cast<std::size_t>(m == params_.noise_window ? (recent_next_ + i) % m : i)];
  };
  double num = 0.0;
  double den = 0.0;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  for (int i = 2; i < m; ++i) {
    const Eigen::Vector2d d = at(i) - 2.0 * at(i - 1) + at(i - 2);
    den += d.squaredNorm();
    if (i > 2) num += d.dot(previous);
    previous = d;
  }
  // A perfectly straight uniform trail has no second differences: nothing to smooth.
  return den > 1e-12 ? num / den : 0.0;
}

bool RlsPathPredictor::UsesLineFit() const {
  if (!params_.adaptive) return true;
  return SecondDifferenceCorrelation() < params_.noise_correlation_threshold;
}

void RlsPathPredictor::Update(double t_s, const Eigen::Vector2d& xy_m) {
  CheckObservation("RlsPathPredictor", n_ > 0, t_last_, t_s, xy_m);
  const double lambda = params_.forgetting;
  if (n_ == 0) {
    t_first_ = t_s;
  } else {
    // Re-express the line at the new time: position += velocity * dt (exact for a line).
    const double dt = t_s - t_last_;
    Eigen::Matrix2d A;
    A << 1.0, dt, 0.0, 1.0;
    theta_ = A * theta_;
    P_ = A * P_ * A.transpose();
  }
  t_last_ = t_s;
  // Regressor of the position now: phi = (1, 0).
  const Eigen::Vector2d phi(1.0, 0.0);
  const Eigen::Vector2d Pphi = P_ * phi;
  const double denom = lambda + phi.dot(Pphi);
  const Eigen::Vector2d gain = Pphi / denom;
  const Eigen::RowVector2d innovation = xy_m.transpose() - phi.transpose() * theta_;
  theta_ += gain * innovation;
  P_ = (P_ - gain * Pphi.transpose()) / lambda;
  P_ = 0.5 * (P_ + P_.transpose());  // keep symmetric against round-off
  const Eigen::Vector2d residual = xy_m - theta_.row(0).transpose();
  residual_sum_ = lambda * residual_sum_ + residual * residual.transpose();
  weight_sum_ = lambda * weight_sum_ + 1.0;
  if (static_cast<int>(recent_.size()) < params_.noise_window) {
    recent_.push_back(xy_m);
    recent_t_.push_back(t_s);
  } else {
    recent_[static_cast<std::size_t>(recent_next_)] = xy_m;
    recent_t_[static_cast<std::size_t>(recent_next_)] = t_s;
    recent_next_ = (recent_next_ + 1) % params_.noise_window;
  }
  ++n_;
}

double RlsPathPredictor::mean_step_s() const {
  return n_ >= 2 ? (t_last_ - t_first_) / (n_ - 1) : 0.0;
}

Eigen::Vector2d RlsPathPredictor::velocity_mps() const {
  return n_ >= 2 ? Eigen::Vector2d(theta_.row(1).transpose()) : Eigen::Vector2d::Zero();
}

std::vector<PredictedPoint> RlsPathPredictor::Predict(int steps, double step_s) const {
  ROMO_THROW_UNLESS(steps >= 0 && step_s > 0.0);
  std::vector<PredictedPoint> out;
  if (n_ == 0) return out;
  // Residual covariance of the fit (two parameters per axis) plus the measurement floor.
  const double sigma2_floor = params_.min_sigma_m * params_.min_sigma_m;
  Eigen::Matrix2d residual_cov = Eigen::Matrix2d::Identity() * sigma2_floor;
  const double dof = weight_sum_ - 2.0;
  if (n_ >= 3 && dof > 0.0) residual_cov += residual_sum_ / dof;
  Eigen::Vector2d position = theta_.row(0).transpose();
  Eigen::Vector2d velocity = velocity_mps();
  const bool line_fit = n_ < 2 || UsesLineFit();
  double last_dt = 0.0;
  if (!line_fit) {
    // The lambda -> 0 limit of the fit: the last two positions define the line.
    const int m = static_cast<int>(recent_.size());
    const int newest = m == params_.noise_window ? (recent_next_ + m - 1) % m : m - 1;
    const int before = (newest + m - 1) % m;
    last_dt = recent_t_[newest] - recent_t_[before];
    position = recent_[newest];
    velocity = (recent_[newest] - recent_[before]) / last_dt;
  }
  out.reserve(static_cast<std::size_t>(steps));
  for (int k = 1; k <= steps; ++k) {
    PredictedPoint p;
    p.dt_s = k * step_s;
    p.xy_m = position + velocity * p.dt_s;
    if (!line_fit) {
      // Velocity from two positions: var(v) = 2 var(p) / dt^2.
      const double r = p.dt_s / last_dt;
      p.cov_m2 = residual_cov * (1.0 + 2.0 * r * r);
    } else if (n_ >= 2) {
      const Eigen::Vector2d phi(1.0, p.dt_s);
      p.cov_m2 = residual_cov * (1.0 + phi.dot(P_ * phi));
    } else {
      // One observation: no velocity yet; the walker can be anywhere a fast walk (2 m/s) takes them.
      const double reach_m = 2.0 * p.dt_s;
      p.cov_m2 = residual_cov + Eigen::Matrix2d::Identity() * reach_m * reach_m;
    }
    out.push_back(p);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
ConstantVelocityPredictor::ConstantVelocityPredictor(const PredictorParams& params)
    : PathPredictor(params) {}

void ConstantVelocityPredictor::Update(double t_s, const Eigen::Vector2d& xy_m) {
  CheckObservation("ConstantVelocityPredictor", n_ > 0, t_last_, t_s, xy_m);
  if (n_ == 0) {
    t_first_ = t_s;
  } else {
    last_dt_ = t_s - t_last_;
    v_ = (xy_m - last_) / last_dt_;
  }
  last_ = xy_m;
  t_last_ = t_s;
  ++n_;
}

double ConstantVelocityPredictor::mean_step_s() const {
  return n_ >= 2 ? (t_last_ - t_first_) / (n_ - 1) : 0.0;
}

std::vector<PredictedPoint> ConstantVelocityPredictor::Predict(int steps, double step_s) const {
  ROMO_THROW_UNLESS(steps >= 0 && step_s > 0.0);
  std::vector<PredictedPoint> out;
  if (n_ == 0) return out;
  const double sigma2 = params_.min_sigma_m * params_.min_sigma_m;
  out.reserve(static_cast<std::size_t>(steps));
  for (int k = 1; k <= steps; ++k) {
    PredictedPoint p;
    p.dt_s = k * step_s;
    p.xy_m = last_ + v_ * p.dt_s;
    double var = sigma2;
    if (n_ >= 2) {
      // Velocity from two positions with error sigma each: var(v) = 2 sigma^2 / dt^2.
      const double r = p.dt_s / last_dt_;
      var = sigma2 * (1.0 + 2.0 * r * r);
    } else {
      const double reach_m = 2.0 * p.dt_s;
      var += reach_m * reach_m;
    }
    p.cov_m2 = Eigen::Matrix2d::Identity() * var;
    out.push_back(p);
  }
  return out;
}

std::unique_ptr<PathPredictor> MakePathPredictor(const PredictorParams& params) {
  if (params.kind == PredictorKind::kRls) return std::make_unique<RlsPathPredictor>(params);
  return std::make_unique<ConstantVelocityPredictor>(params);
}

}  // namespace romo::objects
