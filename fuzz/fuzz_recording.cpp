// The recording reader (drivers recording.hpp) on a file holding the input bytes: the strict
// event scanner, and LogReader assembling frame sets (which decodes every message and the
// calibration YAML carried in the log).
#include "harness.hpp"
#include "romo/drivers/recording.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static romo::fuzz::ScratchFile file(".lcmlog");
  const std::string& path = file.Write(data, size);
  ExpectOnlyRomoError([&] {
    std::int64_t truncated_at = 0;
    romo::drivers::ReadAllEvents(path, &truncated_at);
  });
  ExpectOnlyRomoError([&] {
    romo::drivers::LogReader reader(path);
    // Bounded: a looping reader must not hang the fuzzer (loop is off here anyway).
    for (int i = 0; i < 256 && reader.Next(); ++i) {
      reader.other_events();
    }
    reader.status();
    reader.truncated();
  });
  return 0;
}
