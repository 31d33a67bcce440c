#pragma once
/// Top-view pictures of a pipeline frame (OpenCV): world-aligned (north up), centred on the ego;
/// ground points, obstacle points, boxes with class and track id, predicted pedestrian paths,
/// the ground estimate, parking slots with approach spot, turn and entry path, and the ego.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "romo/pipeline/pipeline.hpp"

namespace romo::viz {

struct TopViewParams {
  int size_px = 800;           ///< square picture
  double span_m = 36.0;        ///< metres shown across the picture
  int max_ground_points = 20000;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// An object's true footprint (a simulated or annotated run), drawn under the detections.
struct TruthOutline {
  std::string class_name;
  std::vector<Eigen::Vector2d> corners_world;  ///< closed polygon, world xy
};

/// Draws @p frame; @p ego_trail (world xy) is drawn as the ego's path when given, @p truth as
/// thin dashed outlines so what was missed or misplaced shows beside what was found.
cv::Mat DrawTopView(const pipeline::FrameResult& frame, const TopViewParams& params,
                    const std::vector<Eigen::Vector2d>& ego_trail = {},
                    const std::string& title = "", const std::vector<TruthOutline>& truth = {});

/// Writes @p image as PNG; @throws romo::Error naming the path when it cannot.
void WritePng(const std::string& path, const cv::Mat& image);

}  // namespace romo::viz
