#pragma once
/// Confidence values of map points (Sec. 3.4.3, Fig. 3.16): counts of supporting and
/// unsupporting observations turned into CV = 1 - exp(-(so/alpha - uo/beta)).
namespace romo::mapping {

/// The four visibility cases of Fig. 3.16.
enum class Visibility {
  kMatched,                 ///< visible and predicted: confidence rises
  kUnpredictedObservation,  ///< visible, nothing predicted it: a new (or noisy) point, initialised
  kUnobservedPrediction,    ///< predicted visible but not observed: confidence falls
  kNotExpected,             ///< neither expected nor observed (occluded / out of view): unchanged
};

struct ConfidenceParams {
  double alpha = 2.0;  ///< learning rate: supporting observations per e-fold
  double beta = 1.0;   ///< forgetting rate: unsupporting observations per e-fold
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct PointEvidence {
  int supported = 0;    ///< so
  int unsupported = 0;  ///< uo
};

/// Applies one visibility case to @p evidence.
void UpdateEvidence(Visibility visibility, PointEvidence* evidence);

/// CV = 1 - exp(-(so/alpha - uo/beta)), clamped to [0, 1): more unsupported than supported
/// evidence means no confidence, not a negative one.
double ConfidenceValue(const PointEvidence& evidence, const ConfidenceParams& params);

}  // namespace romo::mapping
