// Deterministic randomness for the scene generators: a seeded generator with portable
// distributions, hashed gradient noise (optionally tileable) and colour helpers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "renderer/color.hpp"
#include "renderer/math.hpp"

namespace sb::scenes {

/// splitmix64 finaliser: decorrelates seeds and sub-stream ids.
[[nodiscard]] constexpr uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// A seeded random generator. The distributions are written out here rather than taken from
/// <random>, whose distributions differ between standard libraries: the same seed must give the
/// same scene everywhere. `stream` selects an independent sequence for one part of a scene, so
/// that adding objects to one part does not reshuffle the others.
class Rng {
 public:
  explicit Rng(uint64_t seed, uint64_t stream = 0) : engine_(mix64(seed ^ mix64(stream + 0x5eedull))) {}

  [[nodiscard]] uint64_t next() { return engine_(); }
  /// Uniform in [0, 1).
  [[nodiscard]] double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  [[nodiscard]] double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  [[nodiscard]] float uniformf(double lo, double hi) { return static_cast<float>(uniform(lo, hi)); }
  /// Uniform integer in [lo, hi] (inclusive).
  [[nodiscard]] int uniform_int(int lo, int hi) {
    const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi) - lo + 1);
    return lo + static_cast<int>(engine_() % span);
  }
  /// True with probability p.
  [[nodiscard]] bool chance(double p) { return uniform() < p; }
  /// Standard normal (Box-Muller, one value per call).
  [[nodiscard]] double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

 private:
  std::mt19937_64 engine_;
};

/// Integer hash of a lattice point and a seed, in [0, 2^32).
[[nodiscard]] constexpr uint32_t hash3(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  uint64_t h = mix64((static_cast<uint64_t>(static_cast<uint32_t>(x)) << 32) ^ static_cast<uint32_t>(y));
  h = mix64(h ^ (static_cast<uint64_t>(static_cast<uint32_t>(z)) << 17) ^ (static_cast<uint64_t>(seed) << 40));
  return static_cast<uint32_t>(h >> 32);
}

/// 3-D gradient noise (Perlin style, quintic fade), roughly in [-1, 1]. When `period` > 0 the
/// lattice wraps with that period on every axis, so the noise tiles with it.
[[nodiscard]] inline float gradient_noise(const vec3& p, uint32_t seed, int period = 0) {
  const vec3 fl = glm::floor(p);
  const vec3 f = p - fl;
  const int ix = static_cast<int>(fl.x), iy = static_cast<int>(fl.y), iz = static_cast<int>(fl.z);
  auto wrap = [period](int i) { return period > 0 ? ((i % period) + period) % period : i; };
  auto grad = [&](int dx, int dy, int dz) {
    const uint32_t h = hash3(wrap(ix + dx), wrap(iy + dy), wrap(iz + dz), seed);
    // One of 12 edge directions of a cube, as in improved Perlin noise.
    static constexpr float g[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                       {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    const float* v = g[h % 12u];
    return v[0] * (f.x - static_cast<float>(dx)) + v[1] * (f.y - static_cast<float>(dy)) +
           v[2] * (f.z - static_cast<float>(dz));
  };
  auto fade = [](float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); };
  const float u = fade(f.x), v = fade(f.y), w = fade(f.z);
  const float x00 = glm::mix(grad(0, 0, 0), grad(1, 0, 0), u);
  const float x10 = glm::mix(grad(0, 1, 0), grad(1, 1, 0), u);
  const float x01 = glm::mix(grad(0, 0, 1), grad(1, 0, 1), u);
  const float x11 = glm::mix(grad(0, 1, 1), grad(1, 1, 1), u);
  return glm::mix(glm::mix(x00, x10, v), glm::mix(x01, x11, v), w);
}

/// Fractal sum of gradient noise, roughly in [-1, 1]. A positive `period` tiles every octave
/// (the period doubles with the frequency).
[[nodiscard]] inline float fbm(const vec3& p, uint32_t seed, int octaves, int period = 0) {
  float sum = 0.0f, amp = 0.5f, norm = 0.0f;
  vec3 q = p;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * gradient_noise(q, seed + static_cast<uint32_t>(o) * 101u, period);
    norm += amp;
    amp *= 0.5f;
    q *= 2.0f;
    if (period > 0) period *= 2;
  }
  return sum / norm * 1.6f;
}

/// HSV (all in [0, 1]) to linear RGB.
[[nodiscard]] inline vec3 hsv_to_rgb(float h, float s, float v) {
  h = h - std::floor(h);
  const float c = v * s;
  const float hp = h * 6.0f;
  const float x = c * (1.0f - std::fabs(std::fmod(hp, 2.0f) - 1.0f));
  vec3 rgb(0.0f);
  if (hp < 1.0f) rgb = {c, x, 0};
  else if (hp < 2.0f) rgb = {x, c, 0};
  else if (hp < 3.0f) rgb = {0, c, x};
  else if (hp < 4.0f) rgb = {0, x, c};
  else if (hp < 5.0f) rgb = {x, 0, c};
  else rgb = {c, 0, x};
  return rgb + vec3(v - c);
}

/// Smooth step between edges a and b.
[[nodiscard]] inline float smooth(float a, float b, float x) {
  const float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

}  // namespace sb::scenes
