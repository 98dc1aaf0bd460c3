// `full`: the right eye fully ray traced by this suite (plain-rt's right eye, bit for bit).
#include <chrono>

#include <fmt/format.h>

#include "renderer/memory.hpp"
#include "renderer/parallel.hpp"
#include "renderer/stages/trace.hpp"
#include "sb_version.hpp"
#include "validation/providers/providers.hpp"

namespace sb::validation {
namespace {

class FullProvider final : public TruthProvider {
 public:
  std::string name() const override { return "full"; }
  std::string description() const override {
    return "this suite's own ray tracer: plain-rt's right eye (Embree, shading of DESIGN §3); the default";
  }
  std::optional<std::string> unavailable_reason() const override { return std::nullopt; }
  std::string tool_version() const override { return fmt::format("stereobench {}", SB_VERSION_STRING); }
  // The renderer's own version stands for its export and settings.
  std::string revision() const override { return tool_version(); }

  TruthRender render(const TruthRequest& request) const override {
    const auto start = std::chrono::steady_clock::now();
    TruthRender out;
    out.provider = name();
    out.tool_version = tool_version();
    const RigParams& p = request.rig.params();
    require_frame_memory(p.width, p.height, "the 'full' ground truth");
    const Executor executor(request.threads);
    TraceCounts counts;
    out.right = traced_eye(request.scene, request.rig.eye(Eye::right), executor, counts);
    out.settings = {{"pipeline", "plain-rt"}, {"eye", "right"}, {"samples_per_pixel", 1}};
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  }
};

}  // namespace

std::unique_ptr<TruthProvider> make_full_provider() { return std::make_unique<FullProvider>(); }

}  // namespace sb::validation
