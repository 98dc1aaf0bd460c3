// Image quality metrics (DESIGN §6.2): MSE, PSNR, SSIM, error-pixel fraction and maximum error on
// 8-bit sRGB-encoded images, the way the source papers compare, plus a linear-float difference for
// ground-truth provider agreement. Pure functions: images in, numbers out, no I/O, no thresholds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/image.hpp"

namespace sb::validation {

/// Names the exact definitions of every metric below. It is written into every result record;
/// change it whenever a metric's definition changes, so that numbers from different definitions
/// are never compared with each other.
inline constexpr const char* kMetricsVersion =
    "stereobench-metrics 1: srgb8 (clamp [0,1], exact sRGB OETF, round); "
    "mse sum|c-c'|^2/(3n) (Al-Hagri); psnr 10log10(255^2/mse); "
    "ssim Wang 2004 gauss 11x11 sigma 1.5, K1 0.01, K2 0.03, L 255, population covariance, "
    "per channel then averaged, valid crop 5 px; error pixel: max channel |d| > threshold";

/// An 8-bit sRGB-encoded RGB image: width * height * 3 bytes, row-major, row 0 at the top.
struct Srgb8Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;

  [[nodiscard]] std::size_t pixel_count() const noexcept {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
};

/// Encodes a 3-channel float plane (linear radiance, default "rgb") as 8-bit sRGB: each value
/// clamped to [0, 1] (+Inf gives 255, -Inf gives 0), encoded with the exact sRGB OETF and rounded
/// (linear_to_srgb8). InputError if the plane is missing or not 3 x f32, and for NaN samples: the
/// message names the image (`what`), the number of NaN samples and the first NaN pixel (x, y).
[[nodiscard]] Srgb8Image encode_srgb8(const Image& image, std::string_view what, std::string_view plane = planes::rgb);

/// A region of an image: one byte per pixel, row-major, non-zero = inside.
struct RegionMask {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> inside;

  /// Number of pixels inside.
  [[nodiscard]] std::size_t count() const;
  /// A mask of the given size with every pixel inside (`value` true) or outside.
  [[nodiscard]] static RegionMask filled(int width, int height, bool value);
};

/// Options of compare_images.
struct MetricOptions {
  /// An error pixel is one whose largest channel difference exceeds this many 8-bit codes
  /// (default 2, i.e. 2/255). Must lie in 0..255.
  int error_threshold = 2;
};

/// The metrics of one image pair over a region (the whole image when no mask is given).
///
/// An empty region (a mask with no pixel inside) gives pixels = 0 and NaN for mse, psnr, ssim and
/// error_fraction, max_error 0 and max_x = max_y = -1: no number that could pass for a measurement.
struct ImageMetrics {
  std::size_t pixels = 0;  ///< pixels in the region
  double mse = 0.0;        ///< sum over the region of ||c - c'||^2 / (3 * pixels), 0..255 scale
  double psnr = 0.0;       ///< 10 log10(255^2 / mse); +infinity when mse == 0
  /// Mean SSIM over the region's pixels inside the valid region (the pixels whose 11 x 11 window
  /// lies inside the image, i.e. a 5-pixel border is cropped). NaN when there are none: images
  /// smaller than 11 x 11 (scikit-image refuses them) or a region that lies in the border.
  double ssim = 0.0;
  std::size_t ssim_pixels = 0;   ///< pixels the SSIM mean is over
  int error_threshold = 2;       ///< the threshold the error pixels were counted with
  std::size_t error_pixels = 0;  ///< pixels of the region whose max channel difference > error_threshold
  double error_fraction = 0.0;   ///< error_pixels / pixels
  int max_error = 0;             ///< largest channel difference in the region (0..255)
  int max_x = -1, max_y = -1;    ///< first pixel (row-major) with that difference; -1 when it is 0
};

/// MSE over the region (see ImageMetrics::mse); NaN for an empty region. InputError for images of
/// different or zero size, or a mask of another size (all sizes named).
[[nodiscard]] double mse(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region = nullptr);

/// 10 log10(255^2 / mse): +infinity for 0, NaN for NaN.
[[nodiscard]] double psnr_from_mse(double mse);

/// An SSIM map: one value per pixel (the mean of the three channels' SSIM), NaN outside the valid
/// region (a 5-pixel border, everything for images under 11 x 11); `mean` is the mean over the
/// valid region (NaN when it is empty).
struct SsimMap {
  int width = 0;
  int height = 0;
  std::vector<float> values;
  double mean = 0.0;
  std::size_t valid_pixels = 0;
};

/// SSIM of Wang et al. 2004 exactly as scikit-image's structural_similarity(channel_axis=2,
/// gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=255) computes it:
/// an 11 x 11 normalised Gaussian window of sigma 1.5, K1 = 0.01, K2 = 0.03, L = 255, population
/// (co)variances, per channel, then averaged over R, G, B. InputError as for mse().
[[nodiscard]] SsimMap ssim_map(const Srgb8Image& a, const Srgb8Image& b);

/// Every metric of ImageMetrics over the region (the whole image without a mask). InputError as
/// for mse(), and for an error threshold outside 0..255.
[[nodiscard]] ImageMetrics compare_images(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region = nullptr,
                                          const MetricOptions& options = {});

/// compare_images over several regions of one pair (a nullptr entry is the whole image) with the
/// SSIM map computed once; with `map`, that map is stored there too (as ssim_map gives it). The
/// results equal compare_images' region by region. InputError as for compare_images.
[[nodiscard]] std::vector<ImageMetrics> compare_regions(const Srgb8Image& a, const Srgb8Image& b,
                                                        std::span<const RegionMask* const> regions,
                                                        const MetricOptions& options = {}, SsimMap* map = nullptr);

/// A metrics record: metrics_version, pixels, mse, psnr, ssim, ssim_pixels, error_threshold,
/// error_pixels, error_fraction, max_error and max_at ([x, y] or null). An infinite PSNR is
/// written as the string "inf"; NaN values (empty region, no valid SSIM pixel) as null.
[[nodiscard]] nlohmann::json to_json(const ImageMetrics& m);

/// Difference of two linear float "rgb" planes over a region, for provider agreement (§6.1).
/// Empty region: pixels 0, every double NaN, max_x = max_y = -1.
struct LinearDifference {
  std::size_t pixels = 0;
  double mean_abs = 0.0;        ///< mean |a - b| over the region's pixels and the three channels
  double mean_reference = 0.0;  ///< mean of b (the reference) over the same samples
  /// mean_abs / mean_reference (0 when both are 0, +infinity when only the reference is 0)
  double relative = 0.0;
  double max_abs = 0.0;        ///< largest |a - b| of any channel
  int max_x = -1, max_y = -1;  ///< first pixel (row-major) with that difference; -1 when it is 0
};

/// InputError for images of different or zero size, a missing or misshapen "rgb" plane, a mask of
/// another size, or non-finite samples (named with their image, count and first pixel).
[[nodiscard]] LinearDifference linear_difference(const Image& a, const Image& b, const RegionMask* region = nullptr);

/// The "lit" pixels of a pair: where the largest channel of a's or b's "rgb" exceeds `threshold`
/// (linear radiance; NaN samples are not lit). InputError for different sizes, a missing plane or
/// a threshold that is not finite.
[[nodiscard]] RegionMask lit_mask(const Image& a, const Image& b, float threshold);

}  // namespace sb::validation
