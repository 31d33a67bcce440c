// GigE rig configuration YAML (drivers gige.hpp, yaml-cpp). A configuration that validates must
// survive a ToYaml/FromYaml round trip.
#include <string>

#include "harness.hpp"
#include "romo/drivers/gige.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    const auto config = romo::drivers::GigeConfig::FromYaml(text, "fuzz", "/nonexistent");
    const auto again = romo::drivers::GigeConfig::FromYaml(config.ToYaml(), "fuzz round trip", "");
    ROMO_DEMAND(again.rigs.size() == config.rigs.size());
  });
  return 0;
}
