#pragma once
/// The Atlas: object classes with size priors and attributes (config/atlas.yaml), and the
/// classification of a box against them (dissertation 4.1). A box's class always comes from its
/// measured extents, never from ground truth.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "romo/objects/box.hpp"

namespace romo::objects {

/// A Gaussian prior on one extent with hard bounds, metres.
struct SizePrior {
  double mean_m = 0.0;
  double sigma_m = 1.0;
  double min_m = 0.0;
  double max_m = 0.0;
  bool Contains(double x_m) const { return x_m >= min_m && x_m <= max_m; }
};

struct ObjectClass {
  std::string name;
  bool has_priors = false;  ///< false for the fallback "unknown"
  SizePrior length;         ///< footprint, length >= width
  SizePrior width;
  SizePrior height;
  /// Relative frequency in the deployment's surroundings, (0, 1]: between classes whose sizes
  /// explain a box about equally, the commoner one wins.
  double prior = 1.0;
  bool movable = true;
  bool predict_path = false;
  double max_speed_mps = 30.0;
  double max_occlusion_s = 1.0;
};

/// A box's class with its score in [0, 1] (1: every extent at the prior's mean).
struct Classification {
  int class_index = -1;  ///< into Atlas::classes()
  double score = 0.0;
};

class Atlas {
 public:
  /// Loads and validates an Atlas YAML file.
  /// @throws romo::Error naming the file, field and value on any problem.
  static Atlas Load(const std::string& path);
  /// Parses Atlas YAML text; @p source names it in error messages.
  static Atlas Parse(const std::string& yaml_text, const std::string& source);
  /// config/atlas.yaml of the source tree (or ROMO_ATLAS when set).
  static std::string DefaultPath();

  const std::vector<ObjectClass>& classes() const { return classes_; }
  /// Index of the class @p name, or -1.
  int Find(const std::string& name) const;
  /// Index of the class @p name; @throws romo::Error when absent.
  int Require(const std::string& name) const;
  int unknown_index() const { return unknown_; }
  double min_score() const { return min_score_; }

  /// Score of footprint/height extents against one class (0 for the fallback class).
  double Score(int class_index, double length_m, double width_m, double height_m) const;
  /// Best class for extents (length and width are sorted first); "unknown" when no class
  /// reaches min_score, with score 1 - best score.
  Classification Classify(double length_m, double width_m, double height_m) const;
  /// Classify(box.size) for a vertical box.
  Classification Classify(const Box3& box) const;

 private:
  std::vector<ObjectClass> classes_;
  int unknown_ = -1;
  double min_score_ = 0.05;
};

}  // namespace romo::objects
