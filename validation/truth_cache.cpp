// The on-disk cache of ground-truth renders.
#include "validation/truth_cache.hpp"

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "validation/content_hash.hpp"

namespace sb::validation {

using nlohmann::json;


std::string truth_key(const TruthProvider& provider, const TruthRequest& request) {
  Sha256 sha;
  sha.add("stereobench-truth-key 1");
  sha.add(hash_scene(request.scene.scene()));
  const RigParams& p = request.rig.params();
  for (double v : {p.interaxial, p.convergence, p.vfov, p.znear, p.zfar}) sha.add_value(v);
  sha.add_value(p.width);
  sha.add_value(p.height);
  const CameraPose& pose = request.rig.pose();
  for (const dvec3& v : {pose.position, pose.right, pose.up, pose.back}) sha.add_value(v);
  sha.add(provider.name());
  sha.add(provider.revision());
  sha.add(provider.tool_version());
  return sha.hex();
}

std::filesystem::path TruthCache::image_path(const std::string& provider, const std::string& key) const {
  return dir_ / provider / (key + ".exr");
}

std::optional<TruthRender> TruthCache::load(const std::string& provider, const std::string& key) const {
  const std::filesystem::path exr = image_path(provider, key);
  std::filesystem::path meta = exr;
  meta.replace_extension(".json");
  std::error_code ec;
  if (!std::filesystem::exists(meta, ec) || !std::filesystem::exists(exr, ec)) return std::nullopt;
  try {
    const json j = io::parse_json(io::read_file(meta));
    TruthRender r;
    r.right = rgb_plane_only(io::read_exr(exr));
    if (hash_image(r.right) != j.at("image_sha256").get<std::string>()) return std::nullopt;
    r.provider = j.at("provider").get<std::string>();
    r.tool_version = j.at("tool_version").get<std::string>();
    r.settings = j.at("settings");
    r.command = j.at("command").get<std::string>();
    r.seconds = j.at("seconds").get<double>();
    return r;
  } catch (const Error&) {
    return std::nullopt;  // unreadable entry: render again and overwrite it
  } catch (const io::JsonTextError&) {
    return std::nullopt;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

void TruthCache::prepare(const std::string& provider) const {
  const std::filesystem::path folder = dir_ / provider;
  if (const auto why = io::unwritable_folder(folder))
    throw IoError(
        fmt::format("the ground-truth cache {} cannot hold {} renders: {}: {}; give --cache a folder you "
                    "can write, or --cache '' to render without it",
                    dir_.string(), provider, folder.string(), *why));
}

void TruthCache::store(const std::string& key, const TruthRender& render) const {
  const std::filesystem::path exr = image_path(render.provider, key);
  std::filesystem::path meta = exr;
  meta.replace_extension(".json");
  const Image rgb = rgb_plane_only(render.right);
  io::write_exr(exr, rgb);
  const json j = {{"provider", render.provider}, {"tool_version", render.tool_version},
                  {"settings", render.settings},  {"command", render.command},
                  {"seconds", render.seconds},    {"image_sha256", hash_image(rgb)},
                  {"key", key}};
  io::write_text_atomically(meta, j.dump(2) + "\n");
}

ResolvedTruth resolve_truth(const TruthProvider& provider, const TruthRequest& request, const TruthCache* cache) {
  if (auto why = provider.unavailable_reason())
    throw ToolError(fmt::format("ground-truth provider '{}' is unavailable: {}", provider.name(), *why));
  ResolvedTruth out;
  const bool use_cache = cache != nullptr && provider.name() != "full";
  if (use_cache) {
    out.key = truth_key(provider, request);
    if (auto hit = cache->load(provider.name(), out.key)) {
      out.render = std::move(*hit);
      out.cached = true;
      return out;
    }
  }
  if (use_cache) cache->prepare(provider.name());
  out.render = provider.render(request);
  if (use_cache) cache->store(out.key, out.render);
  return out;
}

}  // namespace sb::validation
