// Calibration YAML (drivers calibration.hpp, OpenCV FileStorage): as carried in recordings and
// loaded from files. A calibration that validates must survive a ToYaml/FromYaml round trip.
#include <string>

#include "harness.hpp"
#include "romo/drivers/calibration.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    const auto calibration = romo::drivers::Calibration::FromYaml(text, "fuzz");
    const auto again = romo::drivers::Calibration::FromYaml(calibration.ToYaml(), "fuzz round trip");
    ROMO_DEMAND(again.rigs.size() == calibration.rigs.size());
  });
  return 0;
}
