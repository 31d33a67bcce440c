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

/// Draws @p frame; @p ego_trail (world xy) is drawn as the ego's path when given.
cv::Mat DrawTopView(const pipeline::FrameResult& frame, const TopViewParams& params,
                    const std::vector<Eigen::Vector2d>& ego_trail = {},
                    const std::string& title = "");

/// Writes @p image as PNG; @throws romo::Error naming the path when it cannot.
void WritePng(const std::string& path, const cv::Mat& image);

}  // namespace romo::viz
