// The row-wise 1-D forward warp: motion textures with per-row bounds, and the segmented per-row
// minimum-depth resolve.
#include "renderer/stages/row_warp.hpp"

#include <atomic>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"

namespace sb {

namespace {

/// Winner markers of a target pixel during the resolve (source columns are >= 0).
constexpr int32_t kNoCandidate = -1;
constexpr int32_t kNative = -2;

/// Rows per task when a loop runs over whole rows.
constexpr size_t kRowGrain = 4;

void require_eye_planes(const Image& image, const char* role) {
  for (std::string_view name :
       {planes::rgb, planes::depth, planes::normal, planes::albedo, planes::primid, planes::source})
    if (!image.has_plane(name))
      throw InputError(fmt::format("row warp: the {} image has no '{}' plane (it has {}); make it with make_eye_image",
                                   role, name, image.plane_list()));
}


}  // namespace

DisparityMotion::DisparityMotion(const StereoRig& rig, Eye from) {
  if (from == Eye::center)
    throw InputError("row warp: the centre eye has no other eye to warp into; warp from the left or the right eye");
  const double fe = rig.focal_px() * rig.params().interaxial;
  scale_ = from == Eye::left ? fe : -fe;
  inverse_c_ = 1.0 / rig.params().convergence;
}

void compute_row_bounds(MotionField& field, const Image& source, bool warp_background, const Executor& executor) {
  const int w = field.width, h = field.height;
  if (source.width() != w || source.height() != h || field.motion.size() != static_cast<size_t>(w) * h)
    throw InputError(fmt::format("row warp: motion field of {}x{} ({} values) does not match the {}x{} image", w, h,
                                 field.motion.size(), source.width(), source.height()));
  const float* depth = source.data_f32(planes::depth);
  const uint32_t* tag = source.data_u32(planes::source);
  field.row_min.assign(static_cast<size_t>(h), 0.0f);
  field.row_max.assign(static_cast<size_t>(h), 0.0f);
  executor.for_range(static_cast<size_t>(h), kRowGrain, [&](size_t begin, size_t end) {
    for (size_t y = begin; y < end; ++y) {
      float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
      for (size_t i = y * w; i < (y + 1) * w; ++i) {
        if (!takes_part(tag[i], depth[i], warp_background)) continue;
        lo = std::min(lo, field.motion[i]);
        hi = std::max(hi, field.motion[i]);
      }
      if (lo <= hi) {
        field.row_min[y] = lo;
        field.row_max[y] = hi;
      }
    }
  });
}

MotionField disparity_motion_field(const Image& source, const StereoRig& rig, Eye from, const RowWarpOptions& options,
                                   const Executor& executor) {
  const int w = source.width(), h = source.height();
  if (w != rig.params().width || h != rig.params().height)
    throw InputError(fmt::format("row warp: the source image is {}x{} but the rig renders {}x{}", w, h,
                                 rig.params().width, rig.params().height));
  const DisparityMotion motion(rig, from);
  MotionField field;
  field.width = w;
  field.height = h;
  field.motion.assign(static_cast<size_t>(w) * h, 0.0f);
  field.row_min.assign(static_cast<size_t>(h), 0.0f);
  field.row_max.assign(static_cast<size_t>(h), 0.0f);
  const float* depth = source.data_f32(planes::depth);
  const uint32_t* tag = source.data_u32(planes::source);
  // Motion and row bounds in one pass over each row.
  executor.for_range(static_cast<size_t>(h), kRowGrain, [&](size_t begin, size_t end) {
    for (size_t y = begin; y < end; ++y) {
      float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
      for (size_t i = y * w; i < (y + 1) * w; ++i) {
        if (!takes_part(tag[i], depth[i], options.warp_background)) continue;
        const float m = motion(depth[i]);
        field.motion[i] = m;
        lo = std::min(lo, m);
        hi = std::max(hi, m);
      }
      if (lo <= hi) {
        field.row_min[y] = lo;
        field.row_max[y] = hi;
      }
    }
  });
  return field;
}

RowWarpStats row_warp(const Image& source, const MotionField& motion, const RowWarpOptions& options,
                      const Executor& executor, Image& target) {
  require_eye_planes(source, "source");
  require_eye_planes(target, "target");
  if (&source == &target)
    throw InputError("row warp: source and target are the same image; warp into a copy of the target");
  const int w = source.width(), h = source.height();
  if (target.width() != w || target.height() != h)
    throw InputError(fmt::format("row warp: the source is {}x{} but the target is {}x{}", w, h, target.width(),
                                 target.height()));
  if (motion.width != w || motion.height != h || motion.motion.size() != source.pixel_count() ||
      motion.row_min.size() != static_cast<size_t>(h) || motion.row_max.size() != static_cast<size_t>(h))
    throw InputError(fmt::format("row warp: the motion field ({}x{}) does not match the {}x{} source; make it with "
                                 "disparity_motion_field",
                                 motion.width, motion.height, w, h));
  if (options.segment < 1)
    throw InputError(fmt::format("row warp: segment length {} must be at least 1 pixel", options.segment));

  const EyeReader src(source);
  const float* native_depth = target.data_f32(planes::depth);
  const uint32_t* native_tag = target.data_u32(planes::source);
  EyeWriter out(target);
  const int segment = std::min(options.segment, std::max(w, 1));
  const int segments = (w + segment - 1) / segment;
  const size_t tasks = static_cast<size_t>(h) * static_cast<size_t>(segments);
  std::atomic<uint64_t> total_sources{0}, total_outside{0}, total_landed{0}, total_written{0};

  // One task per (row, target segment); a chunk of tasks shares its scratch buffers.
  executor.for_range(tasks, std::max<size_t>(1, static_cast<size_t>(1024 / segment)), [&](size_t begin, size_t end) {
    std::vector<float> best_depth(static_cast<size_t>(segment));
    std::vector<int32_t> best_x(static_cast<size_t>(segment));
    uint64_t sources = 0, outside = 0, landed = 0, written = 0;
    for (size_t task = begin; task < end; ++task) {
      const int y = static_cast<int>(task / static_cast<size_t>(segments));
      const int s = static_cast<int>(task % static_cast<size_t>(segments));
      const int s0 = s * segment, s1 = std::min(w, s0 + segment);
      const size_t row = static_cast<size_t>(y) * w;

      // The target pixels' own candidates: native pixels, or nothing.
      for (int t = s0; t < s1; ++t) {
        const size_t i = row + t;
        const bool kept = options.keep_native && native_tag[i] != static_cast<uint32_t>(Source::hole);
        const bool native = kept || takes_part(native_tag[i], native_depth[i], options.warp_background);
        best_depth[t - s0] = kept     ? -std::numeric_limits<float>::infinity()
                             : native ? native_depth[i]
                                      : std::numeric_limits<float>::infinity();
        best_x[t - s0] = native ? kNative : kNoCandidate;
      }

      // The source pixels that can land in [s0, s1): column floor(x + 0.5 + m) with m within the
      // row's bounds, widened by a pixel on each side against rounding. The first and the last
      // segment read to the row's ends, so that they count the pixels that leave the row.
      const double lo_motion = motion.row_min[static_cast<size_t>(y)];
      const double hi_motion = motion.row_max[static_cast<size_t>(y)];
      const int x_begin =
          s == 0 ? 0 : static_cast<int>(std::clamp(std::floor(s0 - 0.5 - hi_motion) - 1.0, 0.0, double(w)));
      const int x_end = s1 == w ? w : static_cast<int>(std::clamp(std::ceil(s1 - 0.5 - lo_motion) + 1.0, 0.0, double(w)));

      // Minimum depth per target pixel; ascending x makes the larger source x win exact ties among
      // sources, and a native pixel keeps an exact tie.
      for (int x = x_begin; x < x_end; ++x) {
        const size_t i = row + x;
        const float z = src.depth(i);
        if (!takes_part(src.source(i), z, options.warp_background)) continue;
        const int t = target_column(x, motion.motion[i]);
        if (t < 0 || t >= w) {
          // Counted once: by the first segment for the left side, by the last for the right.
          if ((t < 0 && s == 0) || (t >= w && s1 == w)) {
            ++outside;
            ++sources;
          }
          continue;
        }
        if (t < s0 || t >= s1) continue;
        ++sources;
        ++landed;
        const size_t k = static_cast<size_t>(t - s0);
        if (best_x[k] == kNoCandidate || z < best_depth[k] || (z == best_depth[k] && best_x[k] != kNative)) {
          best_depth[k] = z;
          best_x[k] = x;
        }
      }

      // The winners' values.
      for (int t = s0; t < s1; ++t) {
        const int32_t x = best_x[t - s0];
        if (x < 0) continue;
        const size_t i = row + x;
        out.copy(row + t, src, i, Source::reprojected);
        ++written;
      }
    }
    total_sources += sources;
    total_outside += outside;
    total_landed += landed;
    total_written += written;
  });

  RowWarpStats stats;
  stats.sources = total_sources;
  stats.outside = total_outside;
  stats.landed = total_landed;
  stats.written = total_written;
  stats.occluded = stats.landed - stats.written;
  return stats;
}

Image make_hole_image(int width, int height, const Executor& executor) {
  Image image = make_eye_image(width, height, PlaneInit::unset);  // every pixel is written below
  EyeWriter out(image);
  executor.for_range(image.pixel_count(), 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) out.hole(i);
  });
  return image;
}

}  // namespace sb
