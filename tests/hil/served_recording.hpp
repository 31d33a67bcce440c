#pragma once
// Recordings made to be served by `romo gige-serve` in hardware-in-loop tests: every image is
// textured and different per frame, rig and side, so an image grabbed back says which instant it
// was; helpers check a grabbed recording against what was served.
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::hil {

using drivers::Image;
using drivers::PixelFormat;

inline Image Textured(PixelFormat format, int width, int height, int frame, int rig, int side) {
  Image image = Image::Allocate(format, width, height);
  const int channels = drivers::BytesPerPixel(format) == 3 ? 3 : 1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const unsigned value = (x * 7u + y * 13u + ((x / 8 + y / 8) % 2) * 300u + frame * 101u +
                                rig * 37u + side * 57u + c * 71u) * 2654435761u >> 7;
        if (format == PixelFormat::kMono16) {
          const std::uint16_t sample = value % 4096;  // 12-bit camera values
          std::memcpy(image.row(y) + 2 * x, &sample, 2);
        } else {
          image.row(y)[x * channels + c] = static_cast<std::uint8_t>(value);
        }
      }
    }
  }
  return image;
}

inline bool Same(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.format != b.format) return false;
  const std::size_t row = static_cast<std::size_t>(a.width) * drivers::BytesPerPixel(a.format);
  for (int y = 0; y < a.height; ++y) {
    if (std::memcmp(a.row(y), b.row(y), row) != 0) return false;
  }
  return true;
}

struct Served {
  // frames[rig][k] = {left, right}
  std::vector<std::vector<std::pair<Image, Image>>> frames;
};

/// @p count frame sets at 10 Hz of @p rigs rigs. Formats: the RoMo front rig (rig 0 of several)
/// is colour, the others 12-bit mono; @p format overrides that for every rig.
inline Served WriteRecording(const std::string& path, int rigs, int count, int width, int height,
                             const drivers::Calibration* calibration,
                             std::optional<PixelFormat> format = std::nullopt) {
  constexpr std::int64_t kPeriodNs = 100000000;
  Served served;
  served.frames.resize(rigs);
  drivers::LogWriter writer(path);
  if (calibration) writer.WriteCalibration(*calibration, 0);
  for (int k = 0; k < count; ++k) {
    drivers::FrameSet set;
    set.stamp_ns = (k + 1) * kPeriodNs;
    set.sequence = k;
    for (int rig = 0; rig < rigs; ++rig) {
      const PixelFormat rig_format =
          format ? *format : (rig == 0 && rigs > 1) ? PixelFormat::kRgb8 : PixelFormat::kMono16;
      drivers::StereoFrame stereo;
      stereo.rig_id = rig;
      stereo.left.image = Textured(rig_format, width, height, k, rig, 0);
      stereo.right.image = Textured(rig_format, width, height, k, rig, 1);
      stereo.left.stamp_ns = stereo.right.stamp_ns = set.stamp_ns;
      stereo.left.sequence = stereo.right.sequence = k;
      stereo.left.camera_id = "rig" + std::to_string(rig) + "L";
      stereo.right.camera_id = "rig" + std::to_string(rig) + "R";
      served.frames[rig].push_back({stereo.left.image, stereo.right.image});
      set.stereo.push_back(std::move(stereo));
    }
    writer.Write(set);
  }
  writer.Close();
  return served;
}

/// Index of the served frame @p image equals, or -1.
inline int IndexOf(const std::vector<std::pair<Image, Image>>& frames, const Image& image, bool left) {
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (Same(left ? frames[k].first : frames[k].second, image)) return static_cast<int>(k);
  }
  return -1;
}

/// Why @p image is none of the served frames: its size, whether it is all zero (the emulator's
/// answer to a client that changed size or format), and which served frame each band of rows
/// shows (rows from two frames mean GVSP packets of different frames were assembled together).
inline std::string DescribeUnserved(const std::vector<std::pair<Image, Image>>& frames, const Image& image,
                                    bool left) {
  std::string out = std::to_string(image.width) + "x" + std::to_string(image.height);
  const std::size_t row = static_cast<std::size_t>(image.width) * drivers::BytesPerPixel(image.format);
  bool zero = true;
  for (int y = 0; y < image.height && zero; ++y) {
    for (std::size_t x = 0; x < row; ++x) zero &= image.row(y)[x] == 0;
  }
  out += zero ? ", all zero" : "";
  std::string bands;
  int band_start = 0, band_index = -2;
  auto flush = [&](int end) {
    if (band_index == -2) return;
    bands += " rows " + std::to_string(band_start) + "-" + std::to_string(end - 1) + ": " +
             (band_index < 0 ? std::string("none") : "frame " + std::to_string(band_index)) + ";";
  };
  for (int y = 0; y < image.height; ++y) {
    int match = -1;
    for (std::size_t k = 0; k < frames.size() && match < 0; ++k) {
      const Image& served = left ? frames[k].first : frames[k].second;
      if (served.width == image.width && served.format == image.format && y < served.height &&
          std::memcmp(served.row(y), image.row(y), row) == 0) {
        match = static_cast<int>(k);
      }
    }
    if (match != band_index) {
      flush(y);
      band_start = y;
      band_index = match;
    }
  }
  flush(image.height);
  return out + ";" + bands;
}

struct Check {
  int sets = 0;
  int complete_sets = 0;      // every rig present
  int consecutive_steps = 0;  // served index advanced by exactly one between sets
  int steps = 0;
  std::vector<std::int64_t> stamps_ns;  // per set
  std::vector<int> indices;             // per set: the served frame it shows
};

/// Every recorded image must equal a served one, left and right (and all rigs) the same instant.
inline Check CheckRecorded(const std::string& path, const Served& served) {
  Check check;
  drivers::LogReader reader(path);
  int previous = -1;
  const int count = static_cast<int>(served.frames[0].size());
  while (auto set = reader.Next()) {
    if (set->stereo.empty()) continue;
    ++check.sets;
    check.stamps_ns.push_back(set->stamp_ns);
    int index = -1;
    for (const drivers::StereoFrame& stereo : set->stereo) {
      EXPECT_GE(stereo.rig_id, 0);
      EXPECT_LT(stereo.rig_id, static_cast<int>(served.frames.size()));
      const auto& frames = served.frames[stereo.rig_id];
      const int left = IndexOf(frames, stereo.left.image, true);
      const int right = IndexOf(frames, stereo.right.image, false);
      EXPECT_GE(left, 0) << "rig " << stereo.rig_id << " left image of set " << check.sets
                         << " was never served: " << DescribeUnserved(frames, stereo.left.image, true);
      EXPECT_EQ(left, right) << "rig " << stereo.rig_id << " paired images of different instants (set "
                             << check.sets << ", stamp " << stereo.left.stamp_ns << ", sequence "
                             << stereo.left.sequence << "/" << stereo.right.sequence << ")"
                             << (right < 0 ? "; right never served: " + DescribeUnserved(frames, stereo.right.image, false)
                                           : std::string());
      if (index < 0) index = left;
      EXPECT_EQ(left, index) << "rigs of one frame set show different instants";
      EXPECT_EQ(stereo.left.stamp_ns, stereo.right.stamp_ns);
    }
    check.indices.push_back(index);
    if (set->stereo.size() == served.frames.size()) ++check.complete_sets;
    if (previous >= 0) {
      ++check.steps;
      if (index == (previous + 1) % count) ++check.consecutive_steps;
    }
    previous = index;
  }
  return check;
}

}  // namespace romo::hil
