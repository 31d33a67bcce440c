// Uses the installed romo::drivers: the sample calibration, a recording written and read back.
#include <cstdio>
#include <string>

#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/recording.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: romo_consumer SCRATCH_FOLDER\n");
    return 1;
  }
  try {
    using namespace romo::drivers;
    const Calibration calibration = Calibration::Load(SampleCalibrationPath());
    const std::string path = std::string(argv[1]) + "/consumer.lcmlog";
    {
      LogWriter writer(path);
      writer.WriteCalibration(calibration, 1000);
      FrameSet set;
      set.stamp_ns = 1000;
      StereoFrame stereo;
      stereo.left.image = Image::Allocate(PixelFormat::kMono8, 8, 4);
      stereo.right.image = Image::Allocate(PixelFormat::kMono8, 8, 4);
      set.stereo.push_back(stereo);
      writer.Write(set);
    }
    LogReader reader(path);
    int sets = 0;
    while (reader.Next()) ++sets;
    const bool ok = calibration.rigs.size() == 6 && sets == 1 && reader.calibration() != nullptr;
    std::printf("romo consumer %s: %zu rigs from %s, %d frame set read back\n", ok ? "ok" : "FAILED",
                calibration.rigs.size(), SampleCalibrationPath().c_str(), sets);
    return ok ? 0 : 1;
  } catch (const romo::Error& e) {
    std::fprintf(stderr, "romo consumer: %s\n", e.what());
    return 2;
  }
}
