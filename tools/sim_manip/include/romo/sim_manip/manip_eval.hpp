#pragma once
/// Runs the manipulation plugin on simulated scenes and scores the labels: a confusion matrix
/// over the ten actions and the separation of each pair (Tables 6.1/6.2).
#include <cstdint>
#include <string>
#include <vector>

#include "romo/indoor_manip/manip_analyzer.hpp"
#include "romo/sim_manip/sim_manip.hpp"

namespace romo::sim_manip {

/// The whole plugin on sim-manip://ACTION?seed=N: RANSAC plane, hand seed at the scene's start
/// pixel, every frame.
indoor_manip::ManipResult AnalyzeSimManip(const SimManipOptions& options,
                                          const indoor_manip::ManipParams& params);

struct ConfusionMatrix {
  std::vector<std::string> labels;  ///< ActionNames() plus "error" for failed runs
  std::vector<std::vector<int>> counts;  ///< [truth][predicted]

  ConfusionMatrix();
  void Add(const std::string& truth, const std::string& predicted);
  int Total() const;
  double Accuracy() const;
  /// Runs of one pair member labelled as its partner, summed over both directions.
  int PairConfusions(const std::string& action) const;
  /// Fixed-width table, rows = truth, columns = predicted.
  std::string ToText() const;
  /// {"labels": [...], "counts": [[...], ...] (rows truth), "total", "accuracy",
  ///  "per_action": {action: {"correct", "runs", "recall", "precision"}},
  ///  "pairs": [{"a", "b", "confusions"}]}
  std::string ToJson() const;
};

/// The matrix as a PNG heat map (rows truth, columns predicted, counts written in the cells).
/// @throws romo::Error when the file cannot be written.
void WriteConfusionPng(const ConfusionMatrix& matrix, const std::string& path, const std::string& title);

}  // namespace romo::sim_manip
