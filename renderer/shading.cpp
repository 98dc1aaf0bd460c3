// Lambertian direct lighting with exact shadows (DESIGN §3).
#include "renderer/shading.hpp"

#include <algorithm>
#include <cmath>

namespace sb {

namespace {

constexpr float kInvPi = 0.318309886183790671538f;

}  // namespace

SurfacePoint surface_at(const RenderScene& scene, uint32_t prim, vec2 bary, const vec3& eye) {
  const auto [mesh_index, tri] = scene.geometry().locate(prim);
  const Mesh& mesh = scene.scene().meshes[mesh_index];
  const uint32_t i0 = mesh.indices[tri * 3 + 0], i1 = mesh.indices[tri * 3 + 1], i2 = mesh.indices[tri * 3 + 2];
  const float b1 = bary.x, b2 = bary.y, b0 = 1.0f - b1 - b2;
  SurfacePoint p;
  p.prim = prim;
  p.mesh = mesh_index;
  p.material = mesh.material;
  const vec3& v0 = mesh.positions[i0];
  const vec3& v1 = mesh.positions[i1];
  const vec3& v2 = mesh.positions[i2];
  p.position = b0 * v0 + b1 * v1 + b2 * v2;
  vec3 ng = glm::cross(v1 - v0, v2 - v0);
  const float len = glm::length(ng);
  ng = len > 0.0f ? ng / len : vec3(0.0f, 0.0f, 1.0f);
  const vec3 to_eye = eye - p.position;
  if (glm::dot(ng, to_eye) < 0.0f) ng = -ng;
  p.geometric_normal = ng;
  if (!mesh.normals.empty()) {
    vec3 ns = b0 * mesh.normals[i0] + b1 * mesh.normals[i1] + b2 * mesh.normals[i2];
    const float nl = glm::length(ns);
    ns = nl > 0.0f ? ns / nl : ng;
    // The shading normal turned to the viewer. Near silhouettes of a smooth mesh the interpolated
    // normal can face away from the eye while the triangle faces it; POV-Ray turns such a normal
    // to the viewer and cannot be told otherwise, and the Blender export does the same with a
    // node (docs/truth_blender.md), so all three ground truths shade these pixels alike.
    if (glm::dot(ns, to_eye) < 0.0f) ns = -ns;
    p.shading_normal = ns;
  } else {
    p.shading_normal = ng;
  }
  if (!mesh.uvs.empty()) {
    p.uv = b0 * mesh.uvs[i0] + b1 * mesh.uvs[i1] + b2 * mesh.uvs[i2];
    p.has_uv = true;
  }
  return p;
}

namespace {

/// The material's texture, or -1.
int texture_of(const RenderScene& scene, const SurfacePoint& p) {
  if (p.material < 0 || !p.has_uv) return -1;
  return scene.scene().materials[static_cast<size_t>(p.material)].base_color_texture;
}

}  // namespace

vec3 albedo_at(const RenderScene& scene, const SurfacePoint& p, float lod) {
  if (p.material < 0) return vec3(1.0f);
  const Material& m = scene.scene().materials[static_cast<size_t>(p.material)];
  vec3 c(m.base_color.x, m.base_color.y, m.base_color.z);
  const int t = texture_of(scene, p);
  if (t >= 0) {
    const vec4 tex = scene.texture(t).sample_trilinear(p.uv, lod);
    c *= vec3(tex.x, tex.y, tex.z);
  }
  return c;
}

ConeSection primary_cone(float t, float tan_spread, const vec3& dir, const vec3& view_dir) {
  const float c = glm::dot(dir, view_dir);  // cos(phi)
  // Radial direction: the viewing direction's component across the ray, reversed (pointing away
  // from the axis); its length is sin(phi). On the axis any direction across the ray will do.
  vec3 radial = c * dir - view_dir;
  const float s = glm::length(radial);
  if (s > 1e-6f) {
    radial /= s;
  } else {
    const vec3 helper = std::fabs(dir.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
    radial = glm::normalize(glm::cross(dir, helper));
  }
  const vec3 tangential = glm::cross(dir, radial);
  const float w = t * tan_spread * c;
  return {radial * (w * c), tangential * w};
}

float ray_cone_lod(const RenderScene& scene, const SurfacePoint& p, const ConeSection& cone, const vec3& dir) {
  const int tex = texture_of(scene, p);
  if (tex < 0) return 0.0f;
  const auto [mesh_index, tri] = scene.geometry().locate(p.prim);
  const Mesh& mesh = scene.scene().meshes[mesh_index];
  const uint32_t i0 = mesh.indices[tri * 3 + 0], i1 = mesh.indices[tri * 3 + 1], i2 = mesh.indices[tri * 3 + 2];
  const MipTexture& mt = scene.texture(tex);
  const TexelMap map = triangle_texel_map(mesh.positions[i0], mesh.positions[i1], mesh.positions[i2], mesh.uvs[i0],
                                          mesh.uvs[i1], mesh.uvs[i2], mt.width(), mt.height());
  return lod_from_elliptic_cone(map, cone.axis_a, cone.axis_b, p.geometric_normal, dir);
}

float derivative_lod(const RenderScene& scene, const SurfacePoint& p, const vec4& duv) {
  const int tex = texture_of(scene, p);
  if (tex < 0) return 0.0f;
  const MipTexture& mt = scene.texture(tex);
  return lod_from_derivatives(duv, mt.width(), mt.height());
}

namespace {

/// |n . l| below which a light counts as lying in a triangle's plane: a few hundred times the
/// rounding of a dot product of unit float vectors (~2e-7), about 0.0006 degrees.
constexpr float kInPlane = 1e-5f;

}  // namespace

void shade(const RenderScene& scene, std::span<const SurfacePoint> points, std::span<const vec3> albedo,
           std::span<vec3> radiance, ShadeCounts& counts) {
  const Scene& s = scene.scene();
  const size_t n = points.size();
  const float eps = scene.ray_epsilon();
  for (size_t i = 0; i < n; ++i) radiance[i] = s.ambient * albedo[i];
  RayQuery rays[kRayPacket];
  vec3 contribution[kRayPacket];
  size_t lane_of[kRayPacket];
  uint8_t blocked[kRayPacket];
  for (const Light& light : s.lights) {
    // Unshadowed irradiance per point; points facing away need no shadow ray.
    int active = 0;
    for (size_t i = 0; i < n; ++i) {
      const SurfacePoint& p = points[i];
      vec3 l;
      float dist;
      float e;
      if (light.type == Light::Type::directional) {
        l = -light.direction;
        dist = std::numeric_limits<float>::infinity();
        e = light.intensity;
      } else {
        const vec3 d = light.position - p.position;
        const float r2 = glm::dot(d, d);
        if (r2 <= 0.0f) continue;
        dist = std::sqrt(r2);
        l = d / dist;
        e = light.intensity / r2;
        if (light.type == Light::Type::spot) {
          // KHR_lights_punctual's angular attenuation.
          const float cos_outer = std::cos(light.outer_cone), cos_inner = std::cos(light.inner_cone);
          const float scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
          const float a = std::clamp((glm::dot(light.direction, -l) - cos_outer) * scale, 0.0f, 1.0f);
          e *= a * a;
        }
      }
      const float cos_l = glm::dot(p.shading_normal, l);
      if (cos_l <= 0.0f || e <= 0.0f) continue;
      // Offset the shadow-ray origin to the side of the geometric normal the light is on. A light
      // in the plane of the triangle (within kInPlane, the rounding of the dot product) counts as
      // on the lit side the shading normal found: otherwise rounding would pick the side per
      // pixel, and an origin pushed inside a closed mesh is shadowed by its far side (speckles).
      const float side = glm::dot(p.geometric_normal, l) >= -kInPlane ? 1.0f : -1.0f;
      RayQuery& q = rays[active];
      q.origin = p.position + (side * eps) * p.geometric_normal;
      q.dir = l;
      q.tnear = 0.0f;
      q.tfar = std::isinf(dist) ? dist : dist * (1.0f - 1e-5f);
      contribution[active] = (kInvPi * e * cos_l) * light.color * albedo[i];
      lane_of[active] = i;
      ++active;
    }
    if (active == 0) continue;
    scene.rays().occluded(std::span<const RayQuery>(rays, static_cast<size_t>(active)),
                          std::span<uint8_t>(blocked, static_cast<size_t>(active)));
    counts.shadow_rays += static_cast<uint64_t>(active);
    for (int k = 0; k < active; ++k)
      if (!blocked[k]) radiance[lane_of[k]] += contribution[k];
  }
  counts.pixels_shaded += n;
}

}  // namespace sb
