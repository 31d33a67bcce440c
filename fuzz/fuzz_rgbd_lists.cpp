// The rgbd:// folder source's list files (drivers rgbd_source.cpp): TUM associations.txt, TUM
// rgb.txt + depth.txt and rgbd.match, chosen by the input's first byte, with the rest of the input
// as the list (both TUM lists get it). Images the lists name are not there: opening must parse
// the lists or name what is wrong, and reading a frame must fail naming the missing image.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "harness.hpp"
#include "romo/drivers/frame_source.hpp"

using romo::fuzz::ExpectOnlyRomoError;

namespace {

// A per-process scratch folder, emptied for every input and removed at exit.
struct ScratchFolder {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("romo-fuzz-rgbd-" + std::to_string(::getpid()));
  ~ScratchFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static ScratchFolder folder;
  std::error_code ec;
  std::filesystem::remove_all(folder.path, ec);
  std::filesystem::create_directories(folder.path);
  if (size == 0) return 0;
  const std::string list(reinterpret_cast<const char*>(data) + 1, size - 1);
  auto write = [&](const char* name) { std::ofstream(folder.path / name, std::ios::binary) << list; };
  switch (data[0] % 3) {
    case 0: write("associations.txt"); break;
    case 1: write("rgb.txt"); write("depth.txt"); break;
    default: write("rgbd.match"); break;
  }
  ExpectOnlyRomoError([&] {
    auto source = romo::drivers::OpenSource("rgbd://" + folder.path.string());
    for (int i = 0; i < 3 && source->Next(); ++i) {
    }
  });
  return 0;
}
