// bw-warp: Kim's BW baseline after Bowles et al. (2012, "Iterative Image Warping"): the left eye
// rasterized and shaded; each right pixel searches its source in the same left row by fixed-point
// iteration on the left disparity map, falls back to the background side where the iteration does
// not converge (disocclusions), and what has no source in the left image is left to the crack fill
// or stays a hole.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/crack_fill.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/row_warp.hpp"

namespace sb {
namespace {

/// Where the iteration starts, relative to the right pixel centre x_r.
enum class Start : uint8_t {
  near,    ///< x_r − d_min of the row: the rightmost possible source
  far,     ///< x_r − d_max of the row: the leftmost possible source
  target,  ///< x_r itself (the motion at the target position)
};

/// How the left row is sampled between pixel centres.
enum class Filter : uint8_t { linear, nearest };

/// Two neighbouring left pixels whose disparities differ by this much or more belong to different
/// surfaces: radiance is not interpolated between them.
constexpr float kEdgePx = 0.5f;

/// The fixed point is accepted once the source found moves to within this distance of x_r.
constexpr double kConvergedPx = 0.5;

struct BwSettings {
  RasterOptions raster;
  int iterations = 4;
  Start start = Start::near;
  Filter filter = Filter::linear;
  int max_crack = kDefaultCrackWidth;

  static BwSettings from(const PipelineOptions& options) {
    BwSettings s;
    s.raster = raster_options("bw-warp", options);
    s.iterations = options.get_int("iterations");
    if (s.iterations < 0 || s.iterations > 64)
      throw InputError(fmt::format("bw-warp: option iterations={} is out of range 0..64", s.iterations));
    const std::string& start = options.get("start");
    if (start == "near") s.start = Start::near;
    else if (start == "far") s.start = Start::far;
    else if (start == "target") s.start = Start::target;
    else throw InputError(fmt::format("bw-warp: option start={} is not one of near, far, target", start));
    const std::string& filter = options.get("filter");
    if (filter == "linear") s.filter = Filter::linear;
    else if (filter == "nearest") s.filter = Filter::nearest;
    else throw InputError(fmt::format("bw-warp: option filter={} is not one of linear, nearest", filter));
    s.max_crack = max_crack_option("bw-warp", options);
    return s;
  }
};

/// What became of the right pixels.
struct BackwardCounts {
  uint64_t converged = 0;   ///< a source found (tag reprojected)
  uint64_t fallback = 0;    ///< no convergence: the background side taken (tag inpainted)
  uint64_t holes = 0;       ///< no source inside the left image (tag hole)
  uint64_t iterations = 0;  ///< fixed-point steps taken in all
};

/// One left row: its disparity map and the lookups of the iteration.
class LeftRow {
 public:
  LeftRow(int width, Filter filter) : width_(width), filter_(filter), d_(static_cast<size_t>(width)) {}

  float* disparity() { return d_.data(); }

  /// d(x) at continuous position x: the disparity of the pixel containing x (clamped to the row),
  /// or with linear filtering the interpolation between the pixel centres around x — unless they
  /// lie on two sides of a disparity step (kEdgePx): a silhouette stays a step, so that a thin
  /// foreground surface is not blended away into the background's disparity.
  [[nodiscard]] double d(double x) const {
    if (filter_ == Filter::linear) {
      const double u = x - 0.5;
      const double i0 = std::floor(u);
      const int a = clamp_index(i0), b = clamp_index(i0 + 1.0);
      const float da = d_[static_cast<size_t>(a)], db = d_[static_cast<size_t>(b)];
      if (std::abs(db - da) < kEdgePx) return da + (u - i0) * (db - da);
    }
    return d_[static_cast<size_t>(pixel(x))];
  }

  /// The pixel containing x, clamped to the row.
  [[nodiscard]] int pixel(double x) const { return clamp_index(std::floor(x)); }

  /// The two pixels around x and the weight of the second, for a radiance lookup: t = 0 when they
  /// belong to different surfaces (the nearer pixel centre then decides alone).
  void neighbours(double x, int& a, int& b, float& t) const {
    const double u = x - 0.5;
    const double i0 = std::floor(u);
    a = clamp_index(i0);
    b = clamp_index(i0 + 1.0);
    auto w = static_cast<float>(u - i0);
    if (std::abs(d_[static_cast<size_t>(b)] - d_[static_cast<size_t>(a)]) >= kEdgePx) {
      if (w >= 0.5f) a = b;
      w = 0.0f;
    }
    t = w;
  }

 private:
  [[nodiscard]] int clamp_index(double i) const {
    return static_cast<int>(std::clamp(i, 0.0, static_cast<double>(width_ - 1)));
  }
  int width_;
  Filter filter_;
  std::vector<float> d_;
};

/// The backward warp (stage backward_warp): every right pixel of every row, rows in parallel.
BackwardCounts backward_warp(const Image& left, const StereoRig& rig, const BwSettings& settings,
                             const Executor& executor, Image& right) {
  const int w = left.width(), h = left.height();
  const EyeReader from(left);
  const DisparityMotion motion(rig, Eye::left);
  EyeWriter out(right);
  std::atomic<uint64_t> converged{0}, fallback{0}, holes{0}, steps{0};

  executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
    LeftRow lrow(w, settings.filter);
    BackwardCounts c;
    for (size_t y = begin; y < end; ++y) {
      const size_t row = y * static_cast<size_t>(w);
      // The row's disparity map (the background at the disparity of infinity) and its range.
      float* d = lrow.disparity();
      float d_min = std::numeric_limits<float>::infinity(), d_max = -std::numeric_limits<float>::infinity();
      for (int x = 0; x < w; ++x) {
        d[x] = motion(from.depth(row + x));
        d_min = std::min(d_min, d[x]);
        d_max = std::max(d_max, d[x]);
      }
      for (int xr = 0; xr < w; ++xr) {
        const size_t i = row + xr;
        const double target = xr + 0.5;
        // Fixed-point iteration x <- x_r - d(x), accepted when x + d(x) lies within half a pixel
        // of x_r; the initial guess counts as step 0.
        double x = settings.start == Start::near  ? target - d_min
                   : settings.start == Start::far ? target - d_max
                                                  : target;
        double dx = lrow.d(x);
        double previous = x;
        bool found = std::abs(target - (x + dx)) < kConvergedPx;
        for (int k = 0; k < settings.iterations && !found; ++k) {
          previous = x;
          x = target - dx;
          dx = lrow.d(x);
          found = std::abs(target - (x + dx)) < kConvergedPx;
          ++c.iterations;
        }
        const auto inside = [&](double s) { return s >= 0.0 && s < static_cast<double>(w); };
        Source tag = Source::reprojected;
        if (!found) {
          // A disocclusion: the iteration jumps between the two sides of the gap. Take the farther
          // of the last two positions that lie in the left image: the background side.
          const bool a = inside(previous), b = inside(x);
          if (a && (!b || from.depth(row + lrow.pixel(previous)) > from.depth(row + lrow.pixel(x)))) x = previous;
          found = a || b;
          tag = Source::inpainted;
        }
        if (!found || !inside(x)) {
          // The source lies outside the left image: nothing to copy.
          out.hole(i);
          ++c.holes;
          continue;
        }
        (tag == Source::reprojected ? c.converged : c.fallback)++;
        const size_t s = row + static_cast<size_t>(lrow.pixel(x));
        vec3 radiance = from.rgb(s);
        if (settings.filter == Filter::linear) {
          int a = 0, b = 0;
          float t = 0.0f;
          lrow.neighbours(x, a, b, t);
          radiance = from.rgb(row + a) * (1.0f - t) + from.rgb(row + b) * t;
        }
        out.copy(i, radiance, from.normal(s), from.albedo(s), from.depth(s), from.prim(s), tag);
      }
    }
    converged += c.converged;
    fallback += c.fallback;
    holes += c.holes;
    steps += c.iterations;
  });
  BackwardCounts total;
  total.converged = converged;
  total.fallback = fallback;
  total.holes = holes;
  total.iterations = steps;
  return total;
}

class BwWarp final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Left eye as plain-raster (50 dB, see there; measured 76.24 dB on textured-plane). Right eye
    // against plain-rt on the analytic scenes at 320x180: the strip at the left edge whose sources
    // lie outside the left image stays a hole; lowest measured 26.74 dB (textured-plane, where
    // that strip is 3 px of a bright checker). Hence 26.5 dB.
    static const PipelineInfo i{
        "bw-warp", "Kim (BW baseline); Bowles et al. 2012", "Kim Table 2-3 (BW)",
        "left eye rasterized; each right pixel finds its source by fixed-point iteration on the left disparity map, "
        "the background side at disocclusions",
        {tile_option_spec(),
         {"iterations", "4", "fixed-point steps per right pixel after the initial guess"},
         {"start", "near",
          "initial guess: near = x_r - d_min of the row (favours the nearest surface), far = x_r - d_max, target = x_r"},
         {"filter", "linear",
          "linear: disparity and radiance interpolated between left pixel centres (not across a disparity step of "
          "0.5 px or more); nearest: the left pixel containing the position"},
         {"max_crack", "2",
          "widest run of holes in a row (pixels whose source lies outside the left image, at its borders) filled by "
          "linear interpolation; pixels where the iteration does not converge take the background side instead "
          "(tagged inpainted), so at most rigs this changes nothing"}},
        50.0, 26.5, [](const PipelineOptions& o) { (void)BwSettings::from(o); }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    const BwSettings settings = BwSettings::from(options);
    StereoResult r;
    r.left = raster_eye(scene, rig, Eye::left, settings.raster, ctx.executor, r);
    BackwardCounts counts;
    {
      ScopedStage stage(r.timings, "backward_warp", StageEye::right);
      // backward_warp writes every pixel (a copy or a hole), so the eye needs no fill.
      r.right = make_eye_image(rig.params().width, rig.params().height, PlaneInit::unset);
      counts = backward_warp(r.left, rig, settings, ctx.executor, r.right);
    }
    CrackFillStats cracks;
    {
      ScopedStage stage(r.timings, "crack_fill", StageEye::right);
      cracks = fill_cracks(r.right, settings.max_crack, ctx.executor);
    }
    r.counters.set("converged", counts.converged);
    r.counters.set("fallback", counts.fallback);
    r.counters.set("holes", counts.holes);
    r.counters.set("iterations", counts.iterations);
    r.counters.set("pixels_reprojected_right", counts.converged);
    r.counters.set("hole_pixels", counts.fallback + counts.holes);
    r.counters.set("pixels_inpainted", counts.fallback + cracks.pixels_filled);
    r.counters.set("pixels_filled_fallback", counts.fallback);
    add_crack_counters(r.counters, cracks);
    return r;
  }
};

SB_REGISTER_PIPELINE(BwWarp);

}  // namespace
}  // namespace sb
