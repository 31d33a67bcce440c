#include "romo/mapping/synthetic_scene.hpp"

#include <cmath>
#include <algorithm>
#include <random>

#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

constexpr float kPi = 3.14159265358979f;

struct Sampler {
  std::mt19937_64 rng;
  std::uniform_real_distribution<float> unit{0.f, 1.f};
  std::normal_distribution<float> noise{0.f, 1.f};
  float u() { return unit(rng); }
  std::size_t Count(float area_m2, float density) {
    // Poisson-like rounding keeps the expected density exact for small faces.
    const float expected = area_m2 * density;
    const auto whole = static_cast<std::size_t>(expected);
    return whole + (u() < expected - static_cast<float>(whole) ? 1 : 0);
  }
};

// Points are collected in a flat buffer (PointCloud::PushBack reallocates per point).
struct Collector {
  std::vector<float> xyz;
  std::vector<int> labels;
};

void Add(Collector* out, const Eigen::Vector3f& p, int label, const SyntheticSceneParams& params, Sampler* s) {
  Eigen::Vector3f q = p;
  if (params.noise_m > 0.f) q += params.noise_m * Eigen::Vector3f(s->noise(s->rng), s->noise(s->rng), s->noise(s->rng));
  out->xyz.insert(out->xyz.end(), {q.x(), q.y(), q.z()});
  out->labels.push_back(label);
}

void SampleBox(const SceneObject& o, int label, const SyntheticSceneParams& params, Sampler* s,
               Collector* scene) {
  const float l = o.size.x(), w = o.size.y(), h = o.size.z();
  const Eigen::Matrix2f R = Eigen::Rotation2Df(o.yaw_rad).toRotationMatrix();
  const auto place = [&](float a, float b, float z) {
    const Eigen::Vector2f xy = o.center_xy + R * Eigen::Vector2f(a, b);
    return Eigen::Vector3f(xy.x(), xy.y(), params.ground_height_m + z);
  };
  // Top, four sides; no bottom.
  for (std::size_t k = s->Count(l * w, params.density_per_m2); k-- > 0;)
    Add(scene, place((s->u() - 0.5f) * l, (s->u() - 0.5f) * w, h), label, params, s);
  for (int side = 0; side < 2; ++side) {
    const float sign = side == 0 ? -0.5f : 0.5f;
    for (std::size_t k = s->Count(l * h, params.density_per_m2); k-- > 0;)
      Add(scene, place((s->u() - 0.5f) * l, sign * w, s->u() * h), label, params, s);
    for (std::size_t k = s->Count(w * h, params.density_per_m2); k-- > 0;)
      Add(scene, place(sign * l, (s->u() - 0.5f) * w, s->u() * h), label, params, s);
  }
}

void SampleCylinder(const SceneObject& o, int label, const SyntheticSceneParams& params, Sampler* s,
                    Collector* scene) {
  const float r = 0.5f * o.size.x(), h = o.size.z();
  const auto place = [&](float x, float y, float z) {
    return Eigen::Vector3f(o.center_xy.x() + x, o.center_xy.y() + y, params.ground_height_m + z);
  };
  for (std::size_t k = s->Count(2.f * kPi * r * h, params.density_per_m2); k-- > 0;) {
    const float a = 2.f * kPi * s->u();
    Add(scene, place(r * std::cos(a), r * std::sin(a), s->u() * h), label, params, s);
  }
  for (std::size_t k = s->Count(kPi * r * r, params.density_per_m2); k-- > 0;) {
    const float a = 2.f * kPi * s->u(), rr = r * std::sqrt(s->u());
    Add(scene, place(rr * std::cos(a), rr * std::sin(a), h), label, params, s);
  }
}

}  // namespace

SyntheticScene MakeSyntheticScene(const std::vector<SceneObject>& objects, const SyntheticSceneParams& params) {
  ROMO_THROW_UNLESS(params.density_per_m2 > 0.f && params.noise_m >= 0.f && params.ground_half_extent_m >= 0.f);
  Collector scene;
  Sampler s{std::mt19937_64(params.seed)};
  if (params.ground_half_extent_m > 0.f) {
    const float e = params.ground_half_extent_m;
    for (std::size_t k = s.Count(4.f * e * e, params.density_per_m2); k-- > 0;)
      Add(&scene, Eigen::Vector3f((2.f * s.u() - 1.f) * e, (2.f * s.u() - 1.f) * e, params.ground_height_m), -1,
          params, &s);
  }
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const SceneObject& o = objects[i];
    ROMO_THROW_UNLESS((o.size.array() > 0.f).all());
    if (o.shape == SceneObject::Shape::kBox) {
      SampleBox(o, static_cast<int>(i), params, &s, &scene);
    } else {
      SampleCylinder(o, static_cast<int>(i), params, &s, &scene);
    }
  }
  SyntheticScene out;
  out.objects = objects;
  out.labels = std::move(scene.labels);
  const std::size_t n = out.labels.size();
  out.cloud.Resize(n);
  out.cloud.xyz = Eigen::Map<const Eigen::Matrix3Xf>(scene.xyz.data(), 3, static_cast<Eigen::Index>(n));
  std::fill(out.cloud.sigma_z_m.begin(), out.cloud.sigma_z_m.end(), params.noise_m);
  std::fill(out.cloud.intensity.begin(), out.cloud.intensity.end(), 128.f);
  return out;
}

SyntheticScene MakeParkingScene(std::size_t target_points, std::uint64_t seed, float ground_half_extent_m) {
  ROMO_THROW_UNLESS(target_points > 0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  std::uniform_real_distribution<float> yaw_jitter(-0.05f, 0.05f);
  using Shape = SceneObject::Shape;
  const auto area_of = [](const SceneObject& o) {
    if (o.shape == Shape::kBox) return o.size.x() * o.size.y() + 2.f * (o.size.x() + o.size.y()) * o.size.z();
    const float r = 0.5f * o.size.x();
    return 2.f * kPi * r * o.size.z() + kPi * r * r;
  };
  std::vector<SceneObject> objects;
  float area = 0.f;
  // Pedestrians on the lane, then poles between the rows, then parked cars row by row (nearest
  // rows first, 2.6 m bays, some free) until the cloud reaches target_points at kDensity.
  for (int k = 0; k < 12; ++k) {
    SceneObject ped;
    ped.shape = Shape::kCylinder;
    ped.center_xy = {-16.f + 3.f * static_cast<float>(k) + jitter(rng), static_cast<float>(k % 3 - 1) * 2.5f + jitter(rng)};
    ped.size = {0.5f, 0.5f, 1.75f};
    objects.push_back(ped);
    area += area_of(ped);
  }
  for (int k = 0; k < 10; ++k) {
    SceneObject pole;
    pole.shape = Shape::kCylinder;
    pole.center_xy = {-18.f + 4.f * static_cast<float>(k), (k % 2 ? 1.f : -1.f) * 10.f};
    pole.size = {0.15f, 0.15f, 3.f};
    objects.push_back(pole);
    area += area_of(pole);
  }
  constexpr float kDensity = 450.f;  // points per m^2: a 0.1 m neighbourhood holds ~14 points
  const float needed = static_cast<float>(target_points) / kDensity;
  for (int row = 0; area < needed; ++row) {
    const float row_y = 6.f + 8.f * static_cast<float>(row / 2);
    const float side = row % 2 ? 1.f : -1.f;
    for (int bay = -7; bay <= 7 && area < needed; ++bay) {
      if ((bay + row) % 5 == 0) continue;  // free slots
      SceneObject car;
      car.shape = Shape::kBox;
      car.center_xy = {2.6f * static_cast<float>(bay) + 0.3f * jitter(rng), side * row_y + jitter(rng)};
      car.size = {4.5f, 1.8f, 1.5f};
      car.yaw_rad = 0.5f * kPi + yaw_jitter(rng);
      objects.push_back(car);
      area += area_of(car);
    }
  }
  SyntheticSceneParams params;
  params.ground_half_extent_m = ground_half_extent_m;
  params.density_per_m2 = static_cast<float>(target_points) / area;
  params.noise_m = 0.01f;
  params.seed = seed;
  return MakeSyntheticScene(objects, params);
}

}  // namespace romo::mapping
