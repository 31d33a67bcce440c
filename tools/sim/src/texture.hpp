#pragma once
// Procedural surface appearance: deterministic multi-scale value noise, so stereo matching finds
// texture at every distance (pixel footprints here range from ~3 mm to ~10 cm).
#include <cstdint>

namespace romo::sim::internal {

/// Smoothly interpolated lattice noise in [0, 1) with unit lattice spacing.
float ValueNoise(float x, float y, std::uint32_t seed);

/// Sum over octaves of amplitude[k] * (ValueNoise(p / wavelength[k]) - 0.5). Octaves finer than
/// the ray's footprint @p footprint_m fade out (they would only alias) and are skipped.
float Fbm(float x, float y, std::uint32_t seed, const float* wavelengths_m, const float* amplitudes,
          int octaves, float footprint_m);

/// Reflectance of the asphalt ground at (x, y) metres.
float AsphaltAlbedo(float x, float y, std::uint32_t seed, float footprint_m);
/// Reflectance of worn white paint at (x, y) metres.
float PaintAlbedo(float x, float y, std::uint32_t seed, float footprint_m);

/// Which face of an upright box a ray hit (box frame axes).
enum class Face : std::uint8_t { kMinusX, kPlusX, kMinusY, kPlusY, kTop };

struct SurfacePoint {
  float x, y, z;         ///< hit point in the box frame (origin at the bottom centre), metres
  float hl, hw, height;  ///< half length, half width, height of the box
  Face face;
  float footprint_m;     ///< size of the ray's pixel on the surface
};

float CarAlbedo(const SurfacePoint& p, float base, std::uint32_t seed);
float PedestrianAlbedo(const SurfacePoint& p, float base, std::uint32_t seed);
float CurbAlbedo(const SurfacePoint& p, float base, std::uint32_t seed);
float HedgeAlbedo(const SurfacePoint& p, float base, std::uint32_t seed);

}  // namespace romo::sim::internal
