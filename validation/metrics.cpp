// Image quality metrics on 8-bit sRGB images and linear float differences (DESIGN §6.2).
#include "validation/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "renderer/color.hpp"
#include "renderer/error.hpp"

namespace sb::validation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// SSIM window: 11 x 11 taps (radius 5), Gaussian of sigma 1.5. scikit-image derives the same
/// size from its filter's truncation, int(3.5 * sigma + 0.5) = 5, and crops that radius.
constexpr int kSsimRadius = 5;
constexpr int kSsimWindow = 2 * kSsimRadius + 1;
constexpr double kSsimSigma = 1.5;
constexpr double kC1 = (0.01 * 255.0) * (0.01 * 255.0);
constexpr double kC2 = (0.03 * 255.0) * (0.03 * 255.0);

// ---- Argument checks ---------------------------------------------------------------------------

void check_pair(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region) {
  if (a.width <= 0 || a.height <= 0 || b.width <= 0 || b.height <= 0)
    throw InputError(
        fmt::format("cannot compare an empty image: sizes {}x{} and {}x{}", a.width, a.height, b.width, b.height));
  if (a.width != b.width || a.height != b.height)
    throw InputError(fmt::format("cannot compare images of different sizes: {}x{} and {}x{}; resize or crop one",
                                 a.width, a.height, b.width, b.height));
  for (const Srgb8Image* im : {&a, &b})
    if (im->rgb.size() != im->pixel_count() * 3)
      throw InputError(fmt::format("an 8-bit image of {}x{} holds {} bytes instead of width*height*3 = {}", im->width,
                                   im->height, im->rgb.size(), im->pixel_count() * 3));
  if (region != nullptr) {
    if (region->width != a.width || region->height != a.height)
      throw InputError(fmt::format("the region mask is {}x{} but the images are {}x{}; give a mask of the image size",
                                   region->width, region->height, a.width, a.height));
    if (region->inside.size() != a.pixel_count())
      throw InputError(fmt::format("the region mask of {}x{} holds {} values instead of {}", region->width,
                                   region->height, region->inside.size(), a.pixel_count()));
  }
}

bool in_region(const RegionMask* region, std::size_t pixel) { return region == nullptr || region->inside[pixel] != 0; }

// ---- SSIM ----------------------------------------------------------------------------------------

/// The normalised 1-D Gaussian of the SSIM window as an 11 x 1 CV_64F kernel.
cv::Mat ssim_kernel() {
  cv::Mat k(kSsimWindow, 1, CV_64F);
  double sum = 0.0;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double x = i - kSsimRadius;
    k.at<double>(i) = std::exp(-x * x / (2.0 * kSsimSigma * kSsimSigma));
    sum += k.at<double>(i);
  }
  k /= sum;
  return k;
}

/// Gaussian-weighted local means. Only the valid region (windows inside the image) is used, so
/// the border extrapolation does not matter.
cv::Mat window_mean(const cv::Mat& m, const cv::Mat& kernel) {
  cv::Mat out;
  cv::sepFilter2D(m, out, CV_64F, kernel, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT_101);
  return out;
}

/// Per-pixel SSIM averaged over the three channels (CV_64F, full size; only the valid region is
/// meaningful). Requires images of at least 11 x 11.
cv::Mat ssim_channel_mean(const Srgb8Image& a, const Srgb8Image& b) {
  const cv::Mat kernel = ssim_kernel();
  const cv::Mat ia(a.height, a.width, CV_8UC3, const_cast<uint8_t*>(a.rgb.data()));
  const cv::Mat ib(b.height, b.width, CV_8UC3, const_cast<uint8_t*>(b.rgb.data()));
  std::array<cv::Mat, 3> ca, cb;
  cv::split(ia, ca.data());
  cv::split(ib, cb.data());
  cv::Mat sum = cv::Mat::zeros(a.height, a.width, CV_64F);
  for (int c = 0; c < 3; ++c) {
    cv::Mat x, y;
    ca[static_cast<std::size_t>(c)].convertTo(x, CV_64F);
    cb[static_cast<std::size_t>(c)].convertTo(y, CV_64F);
    const cv::Mat mx = window_mean(x, kernel), my = window_mean(y, kernel);
    const cv::Mat mxx = window_mean(x.mul(x), kernel), myy = window_mean(y.mul(y), kernel);
    const cv::Mat mxy = window_mean(x.mul(y), kernel);
    for (int r = 0; r < a.height; ++r) {
      const double* px = mx.ptr<double>(r);
      const double* py = my.ptr<double>(r);
      const double* pxx = mxx.ptr<double>(r);
      const double* pyy = myy.ptr<double>(r);
      const double* pxy = mxy.ptr<double>(r);
      double* out = sum.ptr<double>(r);
      for (int col = 0; col < a.width; ++col) {
        const double ux = px[col], uy = py[col];
        const double vx = pxx[col] - ux * ux, vy = pyy[col] - uy * uy, cov = pxy[col] - ux * uy;
        out[col] += ((2.0 * ux * uy + kC1) * (2.0 * cov + kC2)) / ((ux * ux + uy * uy + kC1) * (vx + vy + kC2));
      }
    }
  }
  return sum / 3.0;
}

bool ssim_defined(int width, int height) { return width >= kSsimWindow && height >= kSsimWindow; }

/// A double for JSON: null for NaN, "inf"/"-inf" for infinities.
nlohmann::json number_or_null(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

const Plane& rgb_plane(const Image& image, std::string_view what, std::string_view plane) {
  const Plane* p = image.find_plane(plane);
  if (p == nullptr)
    throw InputError(fmt::format("{} has no '{}' plane (planes: {})", what, plane,
                                 image.planes().empty() ? std::string("none") : image.plane_list()));
  if (p->channels() != 3 || p->type() != PlaneType::f32)
    throw InputError(fmt::format("{}: plane '{}' has {} {} channels; the metrics need 3 float channels", what, plane,
                                 p->channels(), to_string(p->type())));
  return *p;
}

}  // namespace

// ---- Encoding ------------------------------------------------------------------------------------

Srgb8Image encode_srgb8(const Image& image, std::string_view what, std::string_view plane) {
  const Plane& p = rgb_plane(image, what, plane);
  Srgb8Image out{image.width(), image.height(), std::vector<uint8_t>(image.pixel_count() * 3)};
  const std::span<const float> v = p.f32();
  std::size_t nan_count = 0, first_nan = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (std::isnan(v[i]) && nan_count++ == 0) first_nan = i / 3;
    out.rgb[i] = linear_to_srgb8(v[i]);  // clamps, so +Inf -> 255 and -Inf -> 0
  }
  if (nan_count > 0) {
    const std::size_t w = static_cast<std::size_t>(image.width());
    throw InputError(
        fmt::format("{} has {} NaN sample(s) in plane '{}', the first at pixel ({}, {}); the metrics "
                    "need finite values: fix the renderer or provider that wrote them",
                    what, nan_count, plane, first_nan % w, first_nan / w));
  }
  return out;
}

// ---- Regions -------------------------------------------------------------------------------------

std::size_t RegionMask::count() const {
  return static_cast<std::size_t>(std::count_if(inside.begin(), inside.end(), [](uint8_t v) { return v != 0; }));
}

RegionMask RegionMask::filled(int width, int height, bool value) {
  if (width < 0 || height < 0) throw InputError(fmt::format("a region mask cannot be {}x{}", width, height));
  return {width, height,
          std::vector<uint8_t>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), value ? 1 : 0)};
}

// ---- 8-bit metrics -------------------------------------------------------------------------------

double mse(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region) {
  check_pair(a, b, region);
  // Integer sums are exact, so the result does not depend on summation order.
  uint64_t squared = 0;
  std::size_t pixels = 0;
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    if (!in_region(region, i)) continue;
    ++pixels;
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = int(a.rgb[i * 3 + c]) - int(b.rgb[i * 3 + c]);
      squared += static_cast<uint64_t>(d * d);
    }
  }
  if (pixels == 0) return kNaN;
  return static_cast<double>(squared) / static_cast<double>(3 * pixels);
}

double psnr_from_mse(double mse) {
  if (std::isnan(mse)) return kNaN;
  if (mse == 0.0) return kInf;
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

namespace {

/// The SSIM map of a pair as an SsimMap (values NaN outside the valid region), from the channel
/// mean of ssim_channel_mean.
SsimMap to_ssim_map(const cv::Mat& s, int width, int height) {
  SsimMap map{width, height, std::vector<float>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                                                std::numeric_limits<float>::quiet_NaN()),
              kNaN, 0};
  double sum = 0.0;
  for (int y = kSsimRadius; y < height - kSsimRadius; ++y) {
    const double* row = s.ptr<double>(y);
    for (int x = kSsimRadius; x < width - kSsimRadius; ++x) {
      map.values[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] =
          static_cast<float>(row[x]);
      sum += row[x];
      ++map.valid_pixels;
    }
  }
  map.mean = sum / static_cast<double>(map.valid_pixels);
  return map;
}

/// Every metric but SSIM over the region (SSIM left NaN).
ImageMetrics pixel_metrics(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region,
                           const MetricOptions& options) {
  ImageMetrics m;
  m.error_threshold = options.error_threshold;
  uint64_t squared = 0;
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    if (!in_region(region, i)) continue;
    ++m.pixels;
    int largest = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = std::abs(int(a.rgb[i * 3 + c]) - int(b.rgb[i * 3 + c]));
      squared += static_cast<uint64_t>(d * d);
      largest = std::max(largest, d);
    }
    if (largest > options.error_threshold) ++m.error_pixels;
    if (largest > m.max_error) {
      m.max_error = largest;
      m.max_x = static_cast<int>(i % static_cast<std::size_t>(a.width));
      m.max_y = static_cast<int>(i / static_cast<std::size_t>(a.width));
    }
  }
  m.ssim = kNaN;
  if (m.pixels == 0) {
    m.mse = m.psnr = m.error_fraction = kNaN;
    return m;
  }
  m.mse = static_cast<double>(squared) / static_cast<double>(3 * m.pixels);
  m.psnr = psnr_from_mse(m.mse);
  m.error_fraction = static_cast<double>(m.error_pixels) / static_cast<double>(m.pixels);
  return m;
}

/// SSIM of `m`: the mean of the channel-mean map `s` over the region's pixels inside the valid region.
void add_ssim(const cv::Mat& s, int width, int height, const RegionMask* region, ImageMetrics& m) {
  if (m.pixels == 0) return;
  double sum = 0.0;
  for (int y = kSsimRadius; y < height - kSsimRadius; ++y) {
    const double* row = s.ptr<double>(y);
    for (int x = kSsimRadius; x < width - kSsimRadius; ++x) {
      if (!in_region(region, static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)))
        continue;
      sum += row[x];
      ++m.ssim_pixels;
    }
  }
  if (m.ssim_pixels > 0) m.ssim = sum / static_cast<double>(m.ssim_pixels);
}

}  // namespace

SsimMap ssim_map(const Srgb8Image& a, const Srgb8Image& b) {
  check_pair(a, b, nullptr);
  if (!ssim_defined(a.width, a.height))
    return SsimMap{a.width, a.height, std::vector<float>(a.pixel_count(), std::numeric_limits<float>::quiet_NaN()),
                   kNaN, 0};
  return to_ssim_map(ssim_channel_mean(a, b), a.width, a.height);
}

std::vector<ImageMetrics> compare_regions(const Srgb8Image& a, const Srgb8Image& b,
                                          std::span<const RegionMask* const> regions, const MetricOptions& options,
                                          SsimMap* map) {
  for (const RegionMask* region : regions) check_pair(a, b, region);
  if (regions.empty()) check_pair(a, b, nullptr);
  if (options.error_threshold < 0 || options.error_threshold > 255)
    throw InputError(
        fmt::format("error threshold {} is out of range; give 0..255 (8-bit codes)", options.error_threshold));
  std::vector<ImageMetrics> out;
  out.reserve(regions.size());
  for (const RegionMask* region : regions) out.push_back(pixel_metrics(a, b, region, options));
  if (!ssim_defined(a.width, a.height)) {
    if (map != nullptr) *map = ssim_map(a, b);
    return out;
  }
  const cv::Mat s = ssim_channel_mean(a, b);
  for (size_t r = 0; r < regions.size(); ++r) add_ssim(s, a.width, a.height, regions[r], out[r]);
  if (map != nullptr) *map = to_ssim_map(s, a.width, a.height);
  return out;
}

ImageMetrics compare_images(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region,
                            const MetricOptions& options) {
  const RegionMask* const regions[] = {region};
  return compare_regions(a, b, regions, options).front();
}

nlohmann::json to_json(const ImageMetrics& m) {
  nlohmann::json j;
  j["metrics_version"] = kMetricsVersion;
  j["pixels"] = m.pixels;
  j["mse"] = number_or_null(m.mse);
  j["psnr"] = number_or_null(m.psnr);
  j["ssim"] = number_or_null(m.ssim);
  j["ssim_pixels"] = m.ssim_pixels;
  j["error_threshold"] = m.error_threshold;
  j["error_pixels"] = m.error_pixels;
  j["error_fraction"] = number_or_null(m.error_fraction);
  j["max_error"] = m.max_error;
  j["max_at"] = m.max_x < 0 ? nlohmann::json(nullptr) : nlohmann::json::array({m.max_x, m.max_y});
  return j;
}

// ---- Linear float ----------------------------------------------------------------------------------

LinearDifference linear_difference(const Image& a, const Image& b, const RegionMask* region) {
  if (a.empty() || b.empty() || a.width() != b.width() || a.height() != b.height())
    throw InputError(
        fmt::format("cannot compare linear images of sizes {}x{} and {}x{}; they must be equal and "
                    "non-empty",
                    a.width(), a.height(), b.width(), b.height()));
  if (region != nullptr &&
      (region->width != a.width() || region->height != a.height() || region->inside.size() != a.pixel_count()))
    throw InputError(fmt::format("the region mask is {}x{} but the images are {}x{}; give a mask of the image size",
                                 region->width, region->height, a.width(), a.height()));
  const std::span<const float> va = rgb_plane(a, "image A", planes::rgb).f32();
  const std::span<const float> vb = rgb_plane(b, "image B (reference)", planes::rgb).f32();
  // Non-finite samples would make every mean meaningless: refuse them with their place.
  for (const auto& [v, name] : {std::pair{va, "image A"}, std::pair{vb, "image B (reference)"}}) {
    const auto bad = std::find_if(v.begin(), v.end(), [](float s) { return !std::isfinite(s); });
    if (bad != v.end()) {
      const std::size_t count =
          static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [](float s) { return !std::isfinite(s); }));
      const std::size_t pixel = static_cast<std::size_t>(bad - v.begin()) / 3;
      const std::size_t w = static_cast<std::size_t>(a.width());
      throw InputError(
          fmt::format("{} has {} non-finite rgb sample(s), the first at pixel ({}, {}); the linear "
                      "difference needs finite radiance",
                      name, count, pixel % w, pixel / w));
    }
  }
  LinearDifference d;
  double abs_sum = 0.0, ref_sum = 0.0;
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    if (!in_region(region, i)) continue;
    ++d.pixels;
    for (std::size_t c = 0; c < 3; ++c) {
      const double diff = std::fabs(double(va[i * 3 + c]) - double(vb[i * 3 + c]));
      abs_sum += diff;
      ref_sum += vb[i * 3 + c];
      if (diff > d.max_abs) {
        d.max_abs = diff;
        d.max_x = static_cast<int>(i % static_cast<std::size_t>(a.width()));
        d.max_y = static_cast<int>(i / static_cast<std::size_t>(a.width()));
      }
    }
  }
  if (d.pixels == 0) {
    d.mean_abs = d.mean_reference = d.relative = d.max_abs = kNaN;
    return d;
  }
  const double samples = 3.0 * static_cast<double>(d.pixels);
  d.mean_abs = abs_sum / samples;
  d.mean_reference = ref_sum / samples;
  d.relative = d.mean_abs == 0.0 ? 0.0 : d.mean_reference == 0.0 ? kInf : d.mean_abs / d.mean_reference;
  return d;
}

RegionMask lit_mask(const Image& a, const Image& b, float threshold) {
  if (!std::isfinite(threshold)) throw InputError(fmt::format("lit threshold {} is not a finite radiance", threshold));
  if (a.width() != b.width() || a.height() != b.height())
    throw InputError(fmt::format("cannot build a lit mask of images of sizes {}x{} and {}x{}", a.width(), a.height(),
                                 b.width(), b.height()));
  const std::span<const float> va = rgb_plane(a, "image A", planes::rgb).f32();
  const std::span<const float> vb = rgb_plane(b, "image B", planes::rgb).f32();
  RegionMask mask = RegionMask::filled(a.width(), a.height(), false);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    bool lit = false;
    for (std::size_t c = 0; c < 3; ++c) lit = lit || va[i * 3 + c] > threshold || vb[i * 3 + c] > threshold;
    mask.inside[i] = lit ? 1 : 0;
  }
  return mask;
}

}  // namespace sb::validation
