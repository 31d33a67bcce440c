// ETH/UCY trajectory import (objects trajectory_eval.hpp) on a file holding the input bytes,
// lenient and strict, then the frame-step inference and (for small sets) the evaluation.
#include "harness.hpp"
#include "romo/objects/trajectory_eval.hpp"

using romo::fuzz::ExpectOnlyRomoError;
namespace obj = romo::objects;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static romo::fuzz::ScratchFile file(".txt");
  const std::string& path = file.Write(data, size);
  ExpectOnlyRomoError([&] { obj::ReadEthUcy(path, /*strict=*/true); });
  ExpectOnlyRomoError([&] {
    const auto set = obj::ReadEthUcy(path, /*strict=*/false);
    obj::InferFrameStep(set);
    if (set.rows_used <= 400) {  // keeps one input's work small
      obj::WindowParams window;
      window.obs = 2;
      window.pred = 3;
      obj::EvaluateTrajectories(set, window, obj::PredictorParams{});
    }
  });
  return 0;
}
