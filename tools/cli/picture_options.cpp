#include "cli/picture_options.hpp"

namespace romo::tools {

void AddPictureOptions(CLI::App& cmd, pipeline::OutputOptions& out) {
  cmd.add_flag_callback("--no-pictures", [&out] { out.frame_pictures = false; },
                        "skip the per-frame top-view PNGs (the stage pictures are still drawn)");
  cmd.add_option("--picture-span", out.picture_span_m,
                 "metres across each top-view picture, centred on the vehicle (smaller zooms in)")
      ->capture_default_str()
      ->check(CLI::Range(2.0, 1000.0));
}

}  // namespace romo::tools
