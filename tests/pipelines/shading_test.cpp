// The shared shading core against closed forms: a plane lit by one point light and by one
// directional light (every pixel to 1e-5 relative), and the shadow of a box under a point light.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/render_scene.hpp"
#include "renderer/scene_geometry.hpp"
#include "renderer/stages/eye_image.hpp"
#include "scenes/generators.hpp"
#include "support/mini_gltf.hpp"
#include "support/render_support.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

/// Radiance of a Lambertian point p with normal n (facing the viewer) and albedo rho under the lights.
dvec3 closed_form(const Scene& s, const dvec3& p, dvec3 n, const dvec3& eye, double rho_r, double rho_g, double rho_b) {
  if (glm::dot(n, eye - p) < 0.0) n = -n;
  dvec3 l_sum(0.0);
  for (const Light& light : s.lights) {
    dvec3 l;
    double e;
    if (light.type == Light::Type::directional) {
      l = -dvec3(light.direction);
      e = light.intensity;
    } else {
      const dvec3 d = dvec3(light.position) - p;
      l = glm::normalize(d);
      e = light.intensity / glm::dot(d, d);
    }
    const double c = std::max(0.0, glm::dot(n, l));
    l_sum += (e * c / kPi) * dvec3(light.color);
  }
  return dvec3(rho_r, rho_g, rho_b) * l_sum + double(s.ambient) * dvec3(rho_r, rho_g, rho_b);
}

/// Renders the lit plane with `pipeline` and checks every pixel against the closed form.
void check_lit_plane(const std::string& pipeline, bool directional) {
  test::ScratchDir dir(pipeline + (directional ? "-sun" : "-point"));
  scenes::GenerateOptions go;
  go.params["directional"] = directional ? 1.0 : 0.0;
  const auto file = scenes::generate("lit-plane", go, dir / "lit-plane.gltf").path;
  const Scene scene = io::load_gltf(file);
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 160, 90);
  const StereoResult r = test::render_with(pipeline, rs, rig);
  const Mesh& plane = scene.meshes.at(0);
  const dvec3 v0(plane.positions[plane.indices[0]]), v1(plane.positions[plane.indices[1]]), v2(plane.positions[plane.indices[2]]);
  const dvec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
  const vec4 rho = scene.materials.at(static_cast<size_t>(plane.material)).base_color;
  size_t checked = 0;
  double worst = 0.0;
  for (Eye e : {Eye::left, Eye::right}) {
    const Image& img = e == Eye::left ? r.left : r.right;
    const EyeCamera cam = rig.eye(e);
    const float* rgb = img.data_f32(planes::rgb);
    const uint32_t* prim = img.data_u32(planes::primid);
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) {
        const size_t i = static_cast<size_t>(y) * img.width() + x;
        if (prim[i] == kNoPrimitive) continue;
        // Exact intersection of the pixel's ray with the plane.
        const dvec3 d = cam.ray_direction(x + 0.5, y + 0.5);
        const double t = glm::dot(v0 - cam.origin, n) / glm::dot(d, n);
        const dvec3 p = cam.origin + t * d;
        const dvec3 want = closed_form(scene, p, n, cam.origin, rho.x, rho.y, rho.z);
        for (int c = 0; c < 3; ++c) {
          const double got = rgb[i * 3 + c];
          const double rel = std::fabs(got - want[c]) / std::max(want[c], 1e-3);
          worst = std::max(worst, rel);
          EXPECT_LE(rel, 1e-5) << pipeline << " " << eye_name(e) << " pixel " << x << "," << y << " channel " << c
                               << " got " << got << " want " << want[c];
        }
        ++checked;
      }
  }
  EXPECT_GT(checked, 2u * 160 * 90 * 9 / 10) << "the plane should fill most of the image";
  std::printf("%s lit plane (%s): %zu pixels, worst relative error %.3g\n", pipeline.c_str(),
              directional ? "directional" : "point", checked, worst);
}

TEST(Shading, LitPlanePointLightMatchesClosedForm) {
  check_lit_plane("plain-rt", false);
  check_lit_plane("plain-raster", false);
}

TEST(Shading, LitPlaneDirectionalLightMatchesClosedForm) {
  check_lit_plane("plain-rt", true);
  check_lit_plane("plain-raster", true);
}

/// Slab test: does the segment from p to q pass through the box?
bool segment_hits_box(const dvec3& p, const dvec3& q, const dvec3& lo, const dvec3& hi) {
  double t0 = 0.0, t1 = 1.0;
  const dvec3 d = q - p;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-15) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - p[a]) / d[a], tb = (hi[a] - p[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

TEST(Shading, BoxShadowBoundaryLiesWhereGeometrySays) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 320, 180);
  const EyeCamera cam = rig.eye(Eye::left);
  int floor_mesh = -1, box_mesh = -1;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (scene.meshes[m].name == "floor") floor_mesh = static_cast<int>(m);
    if (scene.meshes[m].name == "box") box_mesh = static_cast<int>(m);
  }
  ASSERT_GE(floor_mesh, 0);
  ASSERT_GE(box_mesh, 0);
  Bounds3 box;
  for (const vec3& p : scene.meshes[static_cast<size_t>(box_mesh)].positions) box.extend(p);
  const dvec3 light(scene.lights.at(0).position);
  const SceneGeometry& g = rs.geometry();
  for (const std::string pipeline : {"plain-rt", "plain-raster"}) {
    const StereoResult r = test::render_with(pipeline, rs, rig);
    const int w = r.left.width(), h = r.left.height();
    const uint32_t* prim = r.left.data_u32(planes::primid);
    const float* rgb = r.left.data_f32(planes::rgb);
    // Analytic shadow classification of every floor pixel (from its exact floor point).
    std::vector<int> analytic(static_cast<size_t>(w) * h, -1), rendered(static_cast<size_t>(w) * h, -1);
    const float floor_rho = scene.materials.at(static_cast<size_t>(scene.meshes[static_cast<size_t>(floor_mesh)].material)).base_color.x;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (prim[i] == kNoPrimitive || g.locate(prim[i]).first != static_cast<uint32_t>(floor_mesh)) continue;
        const dvec3 d = cam.ray_direction(x + 0.5, y + 0.5);
        const double t = -cam.origin.y / d.y;  // the floor is y = 0
        const dvec3 p = cam.origin + t * d;
        analytic[i] = segment_hits_box(p, light, dvec3(box.lo), dvec3(box.hi)) ? 0 : 1;
        const dvec3 lit = closed_form(scene, p, dvec3(0, 1, 0), cam.origin, floor_rho, floor_rho, floor_rho);
        rendered[i] = rgb[i * 3] > 0.5 * lit.x ? 1 : 0;
      }
    int shadowed = 0, wrong = 0, wrong_far = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (analytic[i] < 0) continue;
        shadowed += analytic[i] == 0;
        if (analytic[i] == rendered[i]) continue;
        ++wrong;
        // A disagreement must lie within one pixel of the analytic boundary.
        bool near_boundary = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            const int a = analytic[static_cast<size_t>(yy) * w + xx];
            if (a >= 0 && a != analytic[i]) near_boundary = true;
          }
        if (!near_boundary) ++wrong_far;
      }
    EXPECT_GT(shadowed, 200) << pipeline << ": the box should cast a visible shadow on the floor";
    EXPECT_EQ(wrong_far, 0) << pipeline << ": " << wrong << " pixels disagree with the analytic shadow, " << wrong_far
                            << " of them more than one pixel from the boundary";
    std::printf("%s box shadow: %d shadowed floor pixels, %d boundary disagreements\n", pipeline.c_str(), shadowed, wrong);
  }
}

TEST(Shading, ALightInAFacesPlaneLightsItEvenly) {
  // A smooth octahedron (vertex normals along the axes) whose face -x-y+z has the point light in
  // its plane: the geometric normal is at right angles to the light, the shading normal turned to
  // it. Rounding must not choose per pixel between an origin outside the mesh (lit) and one
  // inside it (shadowed by the far faces): the face is shaded smoothly, with no dark speckles.
  test::ScratchDir dir("inplane");
  test::MiniGltf g;
  const std::vector<float> dirs = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  std::vector<float> xyz;
  for (size_t i = 0; i < dirs.size(); ++i) xyz.push_back(0.5f * dirs[i] + (i % 3 == 2 ? -4.0f : 0.0f));
  const std::vector<uint32_t> faces = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  const int pos = g.add_positions(xyz);
  const int nrm = g.add_accessor(g.add_view(dirs), 5126, 6, "VEC3");
  const int idx = g.add_accessor(g.add_view(faces), 5125, faces.size(), "SCALAR");
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.1, 0.1, 1}}, {"metallicFactor", 0}}},
                         {"doubleSided", true}}};
  g.add_node({{"mesh", g.add_mesh(nlohmann::json::array(
                           {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}, {"indices", idx}, {"material", 0}}}))}});
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 20}}}}}}};
  // In the face's plane -x - y + (z + 4) = 0.5.
  g.add_node({{"translation", {0.5, 2, -1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  g.write_gltf(dir / "octahedron.gltf");
  const Scene scene = io::load_gltf(dir / "octahedron.gltf");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 200, 200);
  const StereoResult r = test::render_with("plain-rt", rs, rig);
  const int w = r.left.width(), h = r.left.height();
  const uint32_t* prim = r.left.data_u32(planes::primid);
  const float* rgb = r.left.data_f32(planes::rgb);
  const uint32_t face = 2;  // triangle (1, 3, 4): the face -x-y+z
  int pixels = 0, speckles = 0;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (prim[i] != face) continue;
      ++pixels;
      // A dark pixel whose four neighbours on the face are all lit.
      int lit_neighbours = 0, on_face = 0;
      for (const size_t j : {i - 1, i + 1, i - static_cast<size_t>(w), i + static_cast<size_t>(w)}) {
        if (prim[j] != face) continue;
        ++on_face;
        lit_neighbours += rgb[3 * j] > 0.0f ? 1 : 0;
      }
      speckles += rgb[3 * i] == 0.0f && on_face == 4 && lit_neighbours == 4 ? 1 : 0;
    }
  EXPECT_GT(pixels, 500) << "the face should be in view";
  EXPECT_EQ(speckles, 0) << "of " << pixels << " pixels of the face";
}

}  // namespace
}  // namespace sb
