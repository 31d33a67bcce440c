// Source URI parsing (drivers uri.hpp) and the options of the sources that take them without a
// device: sim:// (SimParams::FromUri), sim-manip:// (SimManipOptions::FromUri) and log:// (its
// query, opened on a small recording). A parsed URI must print back to text that parses to the
// same URI.
#include <string>

#include "harness.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/drivers/uri.hpp"
#include "romo/sim/sim_source.hpp"
#include "romo/sim_manip/sim_manip.hpp"

using romo::fuzz::ExpectOnlyRomoError;

namespace {

// A recording of one non-frame event: enough for log:// to open and apply its options.
const std::string& LogPath() {
  static romo::fuzz::ScratchFile file(".lcmlog");
  static const bool written = [] {
    romo::drivers::LogWriter writer(file.path());
    const char payload[] = "x";
    writer.WriteRaw("FUZZ", 1, payload, sizeof payload);
    return true;
  }();
  (void)written;
  return file.path();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ExpectOnlyRomoError([&] {
    auto uri = romo::drivers::Uri::Parse(text);
    const auto again = romo::drivers::Uri::Parse(uri.ToString());
    ROMO_DEMAND(again.scheme == uri.scheme && again.path == uri.path && again.query == uri.query);
    if (uri.scheme == "sim-manip") {
      romo::sim_manip::SimManipOptions::FromUri(uri);
    } else if (uri.scheme == "log") {
      uri.path = LogPath();
      romo::drivers::OpenSource(uri.ToString());
    } else {
      romo::sim::SimParams::FromUri(uri);
    }
  });
  return 0;
}
