// Source URI parsing (drivers uri.hpp) and the sim:// parameters (tools/sim SimParams::FromUri).
// A parsed URI must print back to text that parses to the same URI.
#include <string>

#include "harness.hpp"
#include "romo/drivers/uri.hpp"
#include "romo/sim/sim_source.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    const auto uri = romo::drivers::Uri::Parse(text);
    const auto again = romo::drivers::Uri::Parse(uri.ToString());
    ROMO_DEMAND(again.scheme == uri.scheme && again.path == uri.path && again.query == uri.query);
    romo::sim::SimParams::FromUri(uri);
  });
  return 0;
}
