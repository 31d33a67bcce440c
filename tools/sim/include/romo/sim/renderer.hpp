#pragma once
/// CPU ray caster for the analytic scene: renders every camera of a calibration (with its lens
/// distortion) with regular-grid anti-aliasing and seeded per-pixel sensor noise. Every pixel is
/// a pure function of (scene, seed, frame, camera, pixel), so images are identical for any
/// thread count.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/sim/ground_truth.hpp"
#include "romo/sim/scene.hpp"

namespace romo::sim {

struct RenderParams {
  int samples_per_axis = 2;   ///< anti-aliasing: n x n rays per pixel on a regular grid (1-4)
  double noise_sigma = 2.0;   ///< sensor noise standard deviation in grey levels (0-50)
  int threads = 1;            ///< worker threads (1-256); the output does not depend on it
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

class Renderer {
 public:
  /// Precomputes the ray directions of every camera of @p calibration (distortion included).
  /// @throws romo::Error for invalid parameters or a calibration without rigs.
  Renderer(const drivers::Calibration& calibration, const RenderParams& params);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders all rigs at @p snapshot into mono8 stereo frames (rig order of the calibration;
  /// images, rig ids and camera ids set, stamps left to the caller). When @p depth is not null
  /// it receives the per-pixel truth of every rig (pixel-centre rays).
  std::vector<drivers::StereoFrame> Render(const SceneSnapshot& snapshot, std::uint64_t seed,
                                           std::uint64_t frame, std::vector<GtDepth>* depth) const;

  /// Rays one Render() call casts (without / with depth truth).
  std::uint64_t RaysPerFrame(bool with_depth) const;
  const RenderParams& params() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// @p calibration with every camera resampled by @p scale (image size rounded, focal lengths
/// and principal points scaled about pixel centres), matching what the renderer draws for it.
/// @throws romo::Error when scale is outside (0, 4] or the result has an empty image.
drivers::Calibration ScaleCalibration(const drivers::Calibration& calibration, double scale);

/// Runs fn(i) for i in [0, n) on @p threads threads (the caller included).
void ParallelFor(int n, int threads, const std::function<void(int)>& fn);

}  // namespace romo::sim
