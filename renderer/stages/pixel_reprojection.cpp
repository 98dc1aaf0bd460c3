// Pixel reprojection along scan-lines, restricted-ray validation and the Lemma 1 write counts.
#include "renderer/stages/pixel_reprojection.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/primary_rays.hpp"

namespace sb {

namespace {

enum class RightState : uint8_t { missed = 0, reprojected = kApproved, blocked = 2 };

}  // namespace

PixelReprojector::PixelReprojector(const StereoRig& rig)
    : left_(rig.eye(Eye::left)),
      right_(rig.eye(Eye::right)),
      left_rays_(left_),
      right_rays_(right_),
      motion_(rig, Eye::left),
      width_(rig.params().width) {}

Validation validate_and_copy(const RenderScene& scene, const PixelReprojector& reprojector, const RightSources& sources,
                             const Image& left, const ValidationSettings& settings, const Executor& executor,
                             Image& right) {
  const double margin = settings.margin;
  const int w = sources.width, h = sources.height;
  std::vector<uint8_t> state(static_cast<size_t>(w) * h, static_cast<uint8_t>(RightState::missed));
  std::atomic<uint64_t> rays{0}, absent{0};
  const float* left_depth = left.data_f32(planes::depth);
  const auto length = static_cast<float>(1.0 - margin);
  const PrimaryRays& pixel_rays = reprojector.right_rays();
  // Restricted rays in the 4x4 packets of a whole-eye trace: each reprojected pixel's verdict.
  executor.for_tiles(w, h, kTraceTile, [&](const PixelRect& tile) {
    RayQuery queries[kRayPacket];
    uint32_t where[kRayPacket];
    uint64_t local = 0, local_absent = 0;
    for_pixel_blocks(tile, w, [&](const PixelBlock& block) {
      int m = 0;
      for (int i = 0; i < block.n; ++i) {
        const uint32_t p = block.index[i];
        const int32_t src = sources.column[p];
        if (src == kNoSource) continue;
        RayQuery q = pixel_rays.depth_ray(block.x[i], block.y[i]);
        q.tfar = length * left_depth[p - static_cast<uint32_t>(block.x[i]) + static_cast<uint32_t>(src)];
        queries[m] = q;
        where[m++] = p;
      }
      if (m == 0) return;
      uint8_t blocked[kRayPacket];
      scene.rays().occluded(std::span<const RayQuery>(queries, static_cast<size_t>(m)),
                            std::span<uint8_t>(blocked, static_cast<size_t>(m)));
      local += static_cast<uint64_t>(m);
      if (settings.confirm_surface) {
        // The segment just beyond: the reprojected surface must be there, within the margin.
        RayQuery beyond[kRayPacket];
        uint8_t present[kRayPacket];
        int b = 0;
        int lane[kRayPacket];
        for (int k = 0; k < m; ++k) {
          if (blocked[k]) continue;
          beyond[b] = queries[k];
          beyond[b].tnear = queries[k].tfar;
          beyond[b].tfar = queries[k].tfar * static_cast<float>((1.0 + margin) / (1.0 - margin));
          lane[b++] = k;
        }
        scene.rays().occluded(std::span<const RayQuery>(beyond, static_cast<size_t>(b)),
                              std::span<uint8_t>(present, static_cast<size_t>(b)));
        local += static_cast<uint64_t>(b);
        for (int k = 0; k < b; ++k)
          if (!present[k]) {
            blocked[lane[k]] = 1;
            ++local_absent;
          }
      }
      for (int k = 0; k < m; ++k)
        state[where[k]] = static_cast<uint8_t>(blocked[k] ? RightState::blocked : RightState::reprojected);
    });
    rays += local;
    absent += local_absent;
  });
  // The approved pixels copied row by row (streaming through both images' planes rather than
  // block by block; a row's sources lie in the same row: the rig's baseline is horizontal), the
  // others counted.
  std::atomic<uint64_t> missed{0}, blocked{0};
  executor.for_range(static_cast<size_t>(h), 8, [&](size_t begin, size_t end) {
    const EyeReader from(left);
    EyeWriter out(right);
    uint64_t local_missed = 0, local_blocked = 0;
    for (size_t row = begin * static_cast<size_t>(w); row < end * static_cast<size_t>(w); row += static_cast<size_t>(w))
      for (size_t p = row; p < row + static_cast<size_t>(w); ++p)
        switch (static_cast<RightState>(state[p])) {
          case RightState::reprojected:
            out.copy(p, from, row + static_cast<size_t>(sources.column[p]), Source::reprojected);
            break;
          case RightState::missed: ++local_missed; break;
          case RightState::blocked: ++local_blocked; break;
        }
    missed += local_missed;
    blocked += local_blocked;
  });
  Validation v;
  v.state = std::move(state);
  v.missed = missed;
  v.blocked = blocked;
  v.absent = absent;
  v.restricted_rays = rays;
  return v;
}

void trace_left_eye(const RenderScene& scene, const StereoRig& rig, const Executor& executor, StereoResult& r) {
  TraceCounts left;
  {
    ScopedStage stage(r.timings, "left_trace", StageEye::left);
    r.left = traced_eye(scene, rig.eye(Eye::left), executor, left);
  }
  add_counts(r.counters, left, "left", true);
}

void add_reprojection_counters(const PixelReprojector& reprojector, const StereoRig& rig, const Executor& executor,
                               StereoResult& r) {
  const std::vector<uint64_t> writes = reprojection_writes(reprojector, r.left, executor);
  add_write_counters(r.counters, writes, rig, r.left);
  uint64_t overlapped = 0;
  for (size_t k = 2; k < writes.size(); ++k) overlapped += (k - 1) * writes[k];
  r.counters.set("overlapped", overlapped);
}

void complete_right_eye(const RenderScene& scene, const StereoRig& rig, const PixelReprojector& reprojector,
                        const RightSources& sources, const ValidationSettings& settings, const Executor& executor,
                        StereoResult& r) {
  Validation v;
  {
    ScopedStage stage(r.timings, "validate", StageEye::right);
    // Every pixel is written: approved ones by the copy below, the others by right_trace.
    r.right = make_eye_image(sources.width, sources.height, PlaneInit::unset);
    v = validate_and_copy(scene, reprojector, sources, r.left, settings, executor, r.right);
  }
  TraceCounts counts;
  {
    ScopedStage stage(r.timings, "right_trace", StageEye::right);
    trace_unless(scene, rig.eye(Eye::right), executor, v.state, kApproved, r.right, counts, Source::reshaded_traced);
  }
  add_counts(r.counters, counts, "right", true);
  r.counters.set("missed", v.missed);
  r.counters.set("bad", v.blocked - v.absent);
  if (settings.confirm_surface) r.counters.set("absent", v.absent);
  r.counters.set("restricted_rays", v.restricted_rays);
  r.counters.set("hole_pixels", v.missed + v.blocked);
  r.counters.set("pixels_reprojected_right", static_cast<uint64_t>(r.right.pixel_count()) - v.missed - v.blocked);
}

std::vector<uint64_t> reprojection_writes(const PixelReprojector& reprojector, const Image& left,
                                          const Executor& executor) {
  const int w = left.width(), h = left.height();
  const float* depth = left.data_f32(planes::depth);
  std::vector<uint32_t> writes(static_cast<size_t>(w) * h, 0);
  // A row's reprojections stay in that row: rows are independent.
  executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
    for (size_t y = begin; y < end; ++y)
      for (int x = 0; x < w; ++x) {
        const int32_t t = reprojector.target(x, static_cast<int>(y), depth[y * w + x]);
        if (t != kNoSource) ++writes[y * w + static_cast<size_t>(t)];
      }
  });
  std::vector<uint64_t> histogram(1, 0);
  for (const uint32_t n : writes) {
    if (n >= histogram.size()) histogram.resize(n + 1, 0);
    ++histogram[n];
  }
  return histogram;
}

uint64_t lemma1_bound(const StereoRig& rig, double z_min) {
  const double range = std::ceil(rig.focal_px() * rig.params().interaxial / z_min);
  // Saturated where it does not fit (a rig of a vanishing field of view): a bound, never wrapped.
  constexpr double kLargest = 9.0e18;  // below 2^63, exactly representable
  if (!(range < kLargest)) return static_cast<uint64_t>(kLargest);
  return static_cast<uint64_t>(range) + 1;
}

void add_write_counters(Counters& counters, const std::vector<uint64_t>& histogram, const StereoRig& rig,
                        const Image& left) {
  counters.set("writes_max", histogram.size() - 1);
  for (size_t k = 0; k < histogram.size(); ++k)
    if (histogram[k] > 0) counters.set(fmt::format("writes_per_pixel_{}", k), histogram[k]);
  const std::span<const float> depth = left.plane(planes::depth).f32();
  float z_min = std::numeric_limits<float>::infinity();
  for (const float z : depth)
    if (z > 0.0f) z_min = std::min(z_min, z);
  if (std::isfinite(z_min)) counters.set("writes_bound", lemma1_bound(rig, z_min));
}

std::vector<OptionSpec> validation_option_specs() {
  return {{"margin", "0.01",
           "the validation ray stops this fraction short of the reprojected surface's depth; the thesis's ray runs "
           "the whole depth, but through the rounded pixel's centre it meets a slanted reprojected surface itself "
           "(0 retraced about half of the pixels on spheres); smaller values retrace more and are more exact"},
          {"confirm", "false",
           "also require the reprojected surface within the margin beyond (a second short ray); not in the thesis: "
           "it catches reprojections that land past a silhouette; needs margin > 0"}};
}

ValidationSettings ValidationSettings::from(const std::string& pipeline, const PipelineOptions& options) {
  ValidationSettings s;
  s.margin = options.get_double("margin");
  if (!(s.margin >= 0.0 && s.margin < 1.0))
    throw InputError(fmt::format("{}: option margin={} must lie in [0, 1): the restricted ray stops that fraction "
                                 "short of the reprojected surface",
                                 pipeline, s.margin));
  s.confirm_surface = options.get_bool("confirm");
  // The confirming segment runs from the hit to (1 + m) / (1 - m) of its distance: empty at m = 0,
  // where it found no surface and every reprojected pixel was traced again.
  if (s.confirm_surface && s.margin == 0.0)
    throw InputError(fmt::format("{}: option confirm=true needs margin > 0: the confirming ray looks for the surface "
                                 "within margin beyond the reprojected point, and finds none in an empty segment; "
                                 "give a margin (e.g. the default) or confirm=false",
                                 pipeline));
  return s;
}

}  // namespace sb
