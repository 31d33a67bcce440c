#pragma once
/// The simulator as a frame source: sim://parking?seed=N&frames=M&scale=0.5&depth=1&...
/// Each Next() renders the 12 cameras of the (scaled) sample calibration at 10 Hz and fills the
/// frame set's vehicle state and GNSS fix; the matching ground truth is available alongside.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "romo/drivers/frame_source.hpp"
#include "romo/sim/ground_truth.hpp"
#include "romo/sim/renderer.hpp"
#include "romo/sim/scene.hpp"

namespace romo::sim {

/// Everything that selects a simulated run. URI query keys in brackets.
struct SimParams {
  std::string scene = "parking";       ///< URI path; only "parking" so far
  std::uint64_t seed = 1;              ///< [seed] scene layout, pedestrians, sensor noise
  long long frames = 150;              ///< [frames] > 0; 150 frames cover the whole maneuver
  long long first_frame = 0;           ///< [first] index of the first frame delivered (>= 0)
  double rate_hz = 10.0;               ///< [rate_hz] frame rate, 0.5-100
  double scale = 1.0;                  ///< [scale] image scale (0, 4], calibration scaled to match
  bool depth = false;                  ///< [depth=0|1] per-pixel truth with every frame
  bool distortion = true;              ///< [distortion=0|1] 0 renders (and reports) no distortion
  std::string calibration_path;        ///< [calib] default: the sample calibration
  std::int64_t start_stamp_ns = 1704067200000000000;  ///< [start_ns] 2024-01-01T00:00:00Z
  RenderParams render;  ///< [aa] samples per axis, [noise] sigma, [threads] (URI default: all cores)

  /// @throws romo::Error naming the field and value.
  void Validate() const;
  /// Parses a sim:// URI strictly (unknown keys, bad values and unknown scenes throw).
  static SimParams FromUri(const drivers::Uri& uri);
};

/// The rendered calibration (scaled, distortion as requested) for @p params.
drivers::Calibration SimCalibration(const SimParams& params);

class SimSource : public drivers::FrameSource {
 public:
  /// @throws romo::Error for invalid parameters or an unreadable calibration.
  explicit SimSource(const SimParams& params);
  ~SimSource() override;

  std::optional<drivers::FrameSet> Next() override;
  const drivers::Calibration* calibration() const override;

  /// Truth of the frame set the last Next() returned.
  const GroundTruth& ground_truth() const;
  /// Per-pixel truth of every rig for the last frame (empty unless params.depth).
  const std::vector<GtDepth>& depth() const;
  const ParkingScene& scene() const;
  const SimParams& params() const;
  const Renderer& renderer() const;

  /// Truth at frame @p index without rendering (cheap).
  GroundTruth TruthAt(std::uint64_t index) const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Registers the sim:// scheme with drivers::OpenSource. Idempotent.
void RegisterSimSource();

}  // namespace romo::sim
