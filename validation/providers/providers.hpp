// The ground-truth providers, one file each; validation/truth.cpp is their registry.
#pragma once

#include <memory>
#include <string_view>

#include "renderer/scene.hpp"
#include "validation/truth.hpp"

namespace sb::validation {

/// `full`: plain-rt's right eye, this suite's own ray tracer (the default ground truth).
[[nodiscard]] std::unique_ptr<TruthProvider> make_full_provider();
/// `blender`: Blender Cycles, headless, with the settings of DESIGN §6.1.
[[nodiscard]] std::unique_ptr<TruthProvider> make_blender_provider();
/// `povray`: POV-Ray 3.7 from an SDL export (mesh2), with the settings of DESIGN §6.1.
[[nodiscard]] std::unique_ptr<TruthProvider> make_povray_provider();

/// InputError when a material of the scene is a cut-out (glTF alphaMode MASK): the external
/// providers render every surface opaque, so their truth would show the cut-away parts. Names the
/// material and says which provider to use.
void refuse_cutouts(const Scene& scene, std::string_view provider);

}  // namespace sb::validation
