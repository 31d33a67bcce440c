#include "romo/mapping/confidence.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "romo/core/check.hpp"

namespace romo::mapping {

void ConfidenceParams::Validate() const {
  if (!(alpha > 0)) Fail("confidence.alpha must be > 0, got " + std::to_string(alpha));
  if (!(beta > 0)) Fail("confidence.beta must be > 0, got " + std::to_string(beta));
}

void UpdateEvidence(Visibility visibility, PointEvidence* evidence) {
  ROMO_THROW_UNLESS(evidence != nullptr);
  switch (visibility) {
    case Visibility::kMatched:
      ++evidence->supported;
      break;
    case Visibility::kUnpredictedObservation:
      *evidence = PointEvidence{1, 0};
      break;
    case Visibility::kUnobservedPrediction:
      ++evidence->unsupported;
      break;
    case Visibility::kNotExpected:
      break;
  }
}

double ConfidenceValue(const PointEvidence& e, const ConfidenceParams& p) {
  const double x = e.supported / p.alpha - e.unsupported / p.beta;
  return std::clamp(1.0 - std::exp(-x), 0.0, 1.0);
}

}  // namespace romo::mapping
