#include "texture.hpp"

#include <algorithm>
#include <cmath>

#include "hash.hpp"

namespace romo::sim::internal {
namespace {

float Lattice(std::int32_t ix, std::int32_t iy, std::uint32_t seed) {
  // One hash per lattice point: odd multipliers spread x and y before the mix.
  const std::uint32_t h = Hash32(static_cast<std::uint32_t>(ix) * 0x9E3779B1u +
                                 static_cast<std::uint32_t>(iy) * 0x85EBCA77u + seed);
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

float Clamp01(float v) { return std::min(1.0f, std::max(0.0f, v)); }

// Face coordinates (u along the face, v up or across) so textures do not stretch.
void FaceUv(const SurfacePoint& p, float* u, float* v) {
  switch (p.face) {
    case Face::kMinusX:
    case Face::kPlusX: *u = p.y; *v = p.z; break;
    case Face::kMinusY:
    case Face::kPlusY: *u = p.x; *v = p.z; break;
    case Face::kTop: *u = p.x; *v = p.y; break;
  }
}

}  // namespace

float ValueNoise(float x, float y, std::uint32_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy);
  float tx = x - fx, ty = y - fy;
  tx = tx * tx * (3.0f - 2.0f * tx);
  ty = ty * ty * (3.0f - 2.0f * ty);
  const float a = Lattice(ix, iy, seed), b = Lattice(ix + 1, iy, seed);
  const float c = Lattice(ix, iy + 1, seed), d = Lattice(ix + 1, iy + 1, seed);
  const float top = a + (b - a) * tx;
  const float bottom = c + (d - c) * tx;
  return top + (bottom - top) * ty;
}

float Fbm(float x, float y, std::uint32_t seed, const float* wavelengths_m, const float* amplitudes,
          int octaves, float footprint_m) {
  float sum = 0.0f;
  for (int k = 0; k < octaves; ++k) {
    // Full weight from one footprint per wavelength up, none below half a footprint.
    const float weight = std::min(1.0f, 2.0f * wavelengths_m[k] / footprint_m - 1.0f);
    if (weight <= 0.0f) continue;
    const float inv = 1.0f / wavelengths_m[k];
    // Each octave gets its own lattice; a shear breaks up axis-aligned lattice artefacts.
    const float u = x * inv + 0.37f * y * inv;
    const float v = y * inv - 0.21f * x * inv;
    sum += weight * amplitudes[k] * (ValueNoise(u, v, seed + 0x51ED27u * static_cast<std::uint32_t>(k + 1)) - 0.5f);
  }
  return sum;
}

float AsphaltAlbedo(float x, float y, std::uint32_t seed, float footprint_m) {
  static const float kWave[] = {0.012f, 0.025f, 0.05f, 0.11f, 0.27f, 0.7f, 2.1f};
  static const float kAmp[] = {0.08f, 0.09f, 0.09f, 0.08f, 0.08f, 0.07f, 0.07f};
  return Clamp01(0.32f + Fbm(x, y, seed, kWave, kAmp, 7, footprint_m));
}

float PaintAlbedo(float x, float y, std::uint32_t seed, float footprint_m) {
  static const float kWave[] = {0.02f, 0.06f, 0.2f};
  static const float kAmp[] = {0.08f, 0.08f, 0.1f};
  const float paint = 0.8f + Fbm(x, y, seed ^ 0xA5A5u, kWave, kAmp, 3, footprint_m);
  // Worn patches let the asphalt show through.
  const float wear = ValueNoise(x * 6.0f, y * 6.0f, seed ^ 0x5A5Au);
  return wear < 0.15f ? AsphaltAlbedo(x, y, seed, footprint_m) : Clamp01(paint);
}

float CarAlbedo(const SurfacePoint& p, float base, std::uint32_t seed) {
  static const float kWave[] = {0.02f, 0.045f, 0.1f, 0.22f, 0.5f};
  static const float kAmp[] = {0.10f, 0.10f, 0.09f, 0.07f, 0.05f};
  float u = 0.0f, v = 0.0f;
  FaceUv(p, &u, &v);
  float a = base * (1.0f + 1.6f * Fbm(u, v, seed + static_cast<std::uint32_t>(p.face), kWave, kAmp, 5, p.footprint_m));
  const bool side = p.face == Face::kMinusY || p.face == Face::kPlusY;
  const bool end = p.face == Face::kMinusX || p.face == Face::kPlusX;
  // Windows: a dark band below the roof, inset from the corners, with blurred reflections;
  // wheels: dark rectangles low on the sides with tread and rim texture. Both keep enough
  // contrast for stereo matching.
  static const float kGlassWave[] = {0.025f, 0.06f, 0.15f, 0.4f};
  static const float kGlassAmp[] = {0.07f, 0.08f, 0.08f, 0.08f};
  if ((side || end) && p.z > p.height - 0.55f && p.z < p.height - 0.1f) {
    const float inset = side ? std::abs(p.x) - (p.hl - 0.5f) : std::abs(p.y) - (p.hw - 0.2f);
    if (inset < 0.0f) a = 0.16f + Fbm(u, v, seed ^ 0x6A55u, kGlassWave, kGlassAmp, 4, p.footprint_m);
  }
  if (side && p.z < 0.62f && std::abs(std::abs(p.x) - (p.hl - 0.85f)) < 0.33f) {
    a = 0.1f + 0.8f * Fbm(u, v, seed ^ 0x7EE1u, kGlassWave, kGlassAmp, 4, p.footprint_m);
  }
  // Lights on both ends.
  if (end && p.z > 0.55f && p.z < 0.75f && std::abs(p.y) > p.hw - 0.4f && std::abs(p.y) < p.hw - 0.08f) {
    a = 0.85f;
  }
  return Clamp01(a);
}

float PedestrianAlbedo(const SurfacePoint& p, float base, std::uint32_t seed) {
  static const float kWave[] = {0.015f, 0.035f, 0.08f, 0.18f};
  static const float kAmp[] = {0.12f, 0.12f, 0.10f, 0.08f};
  float u = 0.0f, v = 0.0f;
  FaceUv(p, &u, &v);
  const float rel = p.z / p.height;
  float tone = base;                          // shirt
  if (rel < 0.47f) tone = 0.45f * base + 0.05f;  // trousers
  if (rel > 0.87f) tone = 0.42f;              // head
  if (p.face == Face::kTop) tone = 0.25f;     // hair
  return Clamp01(tone * (1.0f + 1.8f * Fbm(u, v, seed, kWave, kAmp, 4, p.footprint_m)));
}

float CurbAlbedo(const SurfacePoint& p, float base, std::uint32_t seed) {
  static const float kWave[] = {0.015f, 0.04f, 0.12f, 0.6f};
  static const float kAmp[] = {0.08f, 0.08f, 0.06f, 0.06f};
  float u = 0.0f, v = 0.0f;
  FaceUv(p, &u, &v);
  return Clamp01(base + Fbm(u, v, seed, kWave, kAmp, 4, p.footprint_m));
}

float HedgeAlbedo(const SurfacePoint& p, float base, std::uint32_t seed) {
  static const float kWave[] = {0.02f, 0.05f, 0.12f, 0.3f};
  static const float kAmp[] = {0.25f, 0.2f, 0.15f, 0.1f};
  float u = 0.0f, v = 0.0f;
  FaceUv(p, &u, &v);
  return Clamp01(base * (1.0f + 2.0f * Fbm(u, v, seed, kWave, kAmp, 4, p.footprint_m)));
}

}  // namespace romo::sim::internal
