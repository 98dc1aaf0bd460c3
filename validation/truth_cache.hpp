// The truth cache: external providers' renders kept on disk under a content hash of everything
// that determines them (scene content, rig, resolution, provider, its revision and tool version),
// so that a sweep renders each ground truth once.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "validation/truth.hpp"

namespace sb::validation {

/// The cache key of a request for a provider: SHA-256 of hash_scene, every rig parameter and the
/// centre pose, the provider's name, revision() and tool_version().
[[nodiscard]] std::string truth_key(const TruthProvider& provider, const TruthRequest& request);

/// Renders under <dir>/<provider>/<key>.exr with <key>.json beside it (provider, tool version,
/// settings, command, seconds, image hash). Both are written atomically, the EXR first, so an
/// entry is complete exactly when its JSON exists.
class TruthCache {
 public:
  explicit TruthCache(std::filesystem::path dir) : dir_(std::move(dir)) {}
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::filesystem::path image_path(const std::string& provider, const std::string& key) const;

  /// The cached render, or nothing when absent. An entry whose image no longer matches its
  /// recorded hash (edited, truncated), whose record names another key or provider (copied by
  /// hand), or whose samples are unusable counts as absent and is overwritten by the next store().
  [[nodiscard]] std::optional<TruthRender> load(const std::string& provider, const std::string& key) const;
  void store(const std::string& key, const TruthRender& render) const;
  /// Makes the provider's folder and checks that it can be written and that the entry of `key`
  /// can be stored there: called before a render, so that an unusable cache fails before the
  /// external tool runs, not after. IoError naming it.
  void prepare(const std::string& provider, const std::string& key) const;

 private:
  std::filesystem::path dir_;
};

/// Why a ground-truth image cannot be used (NaN, infinite or negative radiance, counted), or
/// nothing when every sample is a radiance.
[[nodiscard]] std::optional<std::string> unusable_samples(const Image& truth);

/// Throws when a fresh render's image cannot be used (unusable_samples): InputError for POV-Ray's
/// half floats overflowing (lights too bright for it), ToolError otherwise, naming the tool's work
/// folder and, when `caching`, that nothing was stored.
void check_truth_samples(const TruthRender& render, const std::filesystem::path& work_dir, bool caching);

/// A ground-truth render and where it came from.
struct ResolvedTruth {
  TruthRender render;
  std::string key;
  bool cached = false;  ///< loaded from the cache rather than rendered now
};

/// Renders the request with the provider, through the cache when one is given. The `full`
/// provider is never cached: it is this suite's own renderer, as fast as a pipeline, and must
/// follow every change to it. An external render runs under an exclusive lock on the request's
/// work folder (runs that share one take turns). ToolError when the provider is unavailable;
/// check_truth_samples' errors for an image with NaN, infinite or negative samples (not stored).
/// A render that cannot be stored (a full disk) is returned all the same, with a warning.
[[nodiscard]] ResolvedTruth resolve_truth(const TruthProvider& provider, const TruthRequest& request,
                                          const TruthCache* cache);

}  // namespace sb::validation
