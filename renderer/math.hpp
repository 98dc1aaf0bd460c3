// Vector and matrix types shared by the renderer (glm, with the conventions of DESIGN §2).
#pragma once

#define GLM_FORCE_XYZW_ONLY
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace sb {

using glm::dmat3;
using glm::dmat4;
using glm::dquat;
using glm::dvec2;
using glm::dvec3;
using glm::dvec4;
using glm::ivec2;
using glm::mat3;
using glm::mat4;
using glm::vec2;
using glm::vec3;
using glm::vec4;

constexpr double kPi = 3.14159265358979323846;

inline double degrees_to_radians(double deg) { return deg * (kPi / 180.0); }
inline double radians_to_degrees(double rad) { return rad * (180.0 / kPi); }

/// Axis-aligned bounding box.
struct Bounds3 {
  vec3 lo{std::numeric_limits<float>::max()};
  vec3 hi{-std::numeric_limits<float>::max()};

  void extend(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Bounds3& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  [[nodiscard]] bool empty() const { return lo.x > hi.x; }
  [[nodiscard]] vec3 extent() const { return empty() ? vec3(0.0f) : hi - lo; }
  [[nodiscard]] vec3 center() const { return 0.5f * (lo + hi); }
};

}  // namespace sb
