// Global triangle numbering.
#include "renderer/scene_geometry.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb {

SceneGeometry::SceneGeometry(const Scene& s) : scene(&s) {
  first_triangle.reserve(s.meshes.size() + 1);
  first_triangle.push_back(0);
  uint64_t total = 0;
  for (const Mesh& m : s.meshes) {
    total += m.triangle_count();
    if (total >= kNoPrimitiveId)
      throw InputError(fmt::format("{}: more than {} triangles; primitive ids are 32-bit", s.path, kNoPrimitiveId - 1));
    first_triangle.push_back(static_cast<uint32_t>(total));
    const bool double_sided = m.material < 0 || s.materials[static_cast<size_t>(m.material)].double_sided;
    single_sided.push_back(double_sided ? 0 : 1);
  }
  // Cut-outs: one level-0 copy of each texture they read (reserved for every texture, so the
  // records' pointers stay valid).
  cutout_textures_.reserve(s.textures.size());
  std::vector<const MipTexture*> level0(s.textures.size(), nullptr);
  std::vector<int> material_cutout(s.materials.size(), -1);
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const Material& mat = s.materials[i];
    if (mat.alpha_mode != Material::AlphaMode::mask) continue;
    const MipTexture* texture = nullptr;
    if (const int t = mat.base_color_texture; t >= 0 && static_cast<size_t>(t) < s.textures.size()) {
      if (level0[static_cast<size_t>(t)] == nullptr)
        level0[static_cast<size_t>(t)] = &cutout_textures_.emplace_back(s.textures[static_cast<size_t>(t)], false);
      texture = level0[static_cast<size_t>(t)];
    }
    material_cutout[i] = static_cast<int>(cutouts.size());
    cutouts.push_back(Cutout{texture, mat.base_color.w, mat.alpha_cutoff});
  }
  cutout_of.reserve(s.meshes.size());
  for (const Mesh& m : s.meshes)
    cutout_of.push_back(m.material >= 0 && static_cast<size_t>(m.material) < s.materials.size()
                            ? material_cutout[static_cast<size_t>(m.material)]
                            : -1);
}

const std::vector<uint8_t>& SceneGeometry::closed(const Executor& executor) const {
  const std::lock_guard<std::mutex> lock(closed_mutex_);
  if (!closed_) {
    const Scene& s = *scene;
    std::vector<uint8_t> flags(s.meshes.size(), 0);
    // Each decision is the mesh's own, so the flags do not depend on the thread count.
    executor.for_each(s.meshes.size(), [&](size_t m) {
      flags[m] = single_sided[m] == 0 && cutout_of[m] < 0 && s.meshes[m].is_closed() ? 1 : 0;
    });
    closed_ = std::move(flags);
  }
  return *closed_;
}

void SceneGeometry::forget_closed() {
  const std::lock_guard<std::mutex> lock(closed_mutex_);
  closed_.reset();
}

bool SceneGeometry::opaque_at(uint32_t mesh, uint32_t tri, vec2 bary) const {
  const int32_t c = cutout_of[mesh];
  if (c < 0) return true;
  const Cutout& cut = cutouts[static_cast<size_t>(c)];
  float alpha = cut.factor_alpha;
  const Mesh& m = scene->meshes[mesh];
  if (cut.texture != nullptr && !m.uvs.empty()) {
    const uint32_t* idx = &m.indices[3 * static_cast<size_t>(tri)];
    const float b1 = bary.x, b2 = bary.y, b0 = 1.0f - b1 - b2;
    const vec2 uv = b0 * m.uvs[idx[0]] + b1 * m.uvs[idx[1]] + b2 * m.uvs[idx[2]];
    alpha *= cut.texture->sample_bilinear(uv, 0).w;
  }
  return alpha >= cut.cutoff;
}

std::pair<uint32_t, uint32_t> SceneGeometry::locate(uint32_t prim_id) const {
  const auto it = std::upper_bound(first_triangle.begin(), first_triangle.end(), prim_id);
  const auto mesh = static_cast<uint32_t>(it - first_triangle.begin() - 1);
  return {mesh, prim_id - first_triangle[mesh]};
}

}  // namespace sb
