// Calibration YAML (drivers calibration.hpp, yaml-cpp): as carried in recordings and loaded from
// files. A calibration that validates must survive a ToYaml/FromYaml round trip bit for bit: the
// round trip failing, or changing a value, is a crash.
#include <string>

#include "harness.hpp"
#include "romo/drivers/calibration.hpp"

using romo::drivers::Calibration;
using romo::drivers::RigCalibration;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Calibration calibration;
  try {
    calibration = Calibration::FromYaml(text, "fuzz");
  } catch (const romo::Error&) {
    return 0;
  }
  // Outside the try: a romo::Error here is a writer/reader mismatch, not a rejected input.
  const Calibration again = Calibration::FromYaml(calibration.ToYaml(), "fuzz round trip");
  ROMO_DEMAND(again.rigs.size() == calibration.rigs.size());
  for (std::size_t i = 0; i < again.rigs.size(); ++i) {
    const RigCalibration& a = calibration.rigs[i];
    const RigCalibration& b = again.rigs[i];
    ROMO_DEMAND(a.rig_id == b.rig_id && a.name == b.name && a.width_px == b.width_px &&
                a.height_px == b.height_px);
    ROMO_DEMAND(a.left.K == b.left.K && a.right.K == b.right.K);
    ROMO_DEMAND(a.left.distortion == b.left.distortion &&
                a.right.distortion == b.right.distortion);
    ROMO_DEMAND(a.R == b.R && a.T == b.T && a.T_vehicle_rig.matrix() == b.T_vehicle_rig.matrix());
  }
  return 0;
}
