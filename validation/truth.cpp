// The registry of ground-truth providers.
#include "validation/truth.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"
#include "validation/providers/providers.hpp"

namespace sb::validation {

std::vector<std::string> truth_warnings(const TruthRender& render) {
  std::vector<std::string> out;
  const nlohmann::json& s = render.settings;
  if (const auto it = s.find("export_warnings"); it != s.end() && it->is_array())
    for (const nlohmann::json& w : *it)
      if (w.is_string()) out.push_back(fmt::format("{} truth: {}", render.provider, w.get<std::string>()));
  if (const auto it = s.find("textures_wrapped_on_both_axes"); it != s.end() && it->is_array() && !it->empty())
    out.push_back(fmt::format("{} truth: texture(s) {} repeat along one axis and clamp along the other; Blender "
                              "repeats them along both",
                              render.provider, it->dump()));
  if (render.right.has_plane(planes::rgb))
    if (const double clipped = clipped_fraction(render.right); clipped > kOverExposedFraction)
      out.push_back(fmt::format(
          "{} truth: {:.1f} % of the right eye's pixels are over-exposed (a channel at 1.0 or more, 255 in the 8-bit "
          "images the metrics compare), where no pipeline's error can show; lower the lights' intensities. A file "
          "exported from Blender with its 'Standard' lighting mode gives a P watt point light as 683·P/4π cd, 683 "
          "times the W/sr read here: export with Lighting Mode 'Unitless' (README, Conventions)",
          render.provider, 100.0 * clipped));
  return out;
}

double clipped_fraction(const Image& image) {
  const Plane& rgb = image.plane(planes::rgb);
  const float* v = rgb.data_f32();
  const size_t n = image.pixel_count();
  if (n == 0) return 0.0;
  size_t clipped = 0;
  for (size_t i = 0; i < n; ++i)
    clipped += !(v[i * 3] < 1.0f && v[i * 3 + 1] < 1.0f && v[i * 3 + 2] < 1.0f);
  return static_cast<double>(clipped) / static_cast<double>(n);
}

Image rgb_plane_only(const Image& image) {
  Image out(image.width(), image.height());
  const Plane& src = image.plane(planes::rgb);
  std::copy_n(src.data_f32(), src.value_count(), out.add_plane(planes::rgb).data_f32());
  return out;
}

void TruthProvider::check_scene(const Scene& /*scene*/, const std::filesystem::path& /*scene_file*/) const {}

std::optional<std::string> TruthProvider::prepare(const TruthRequest& /*request*/) const { return std::nullopt; }

std::vector<std::string> truth_provider_names() { return {"full", "blender", "povray"}; }

std::unique_ptr<TruthProvider> make_truth_provider(std::string_view name) {
  if (name == "full") return make_full_provider();
  if (name == "blender") return make_blender_provider();
  if (name == "povray") return make_povray_provider();
  throw InputError(fmt::format("unknown ground-truth provider '{}'; choose one of: {}", name,
                               fmt::join(truth_provider_names(), ", ")));
}

}  // namespace sb::validation
