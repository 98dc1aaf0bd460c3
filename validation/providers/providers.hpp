// The ground-truth providers, one file each; validation/truth.cpp is their registry.
#pragma once

#include <memory>

#include "validation/truth.hpp"

namespace sb::validation {

/// `full`: plain-rt's right eye, this suite's own ray tracer (the default ground truth).
[[nodiscard]] std::unique_ptr<TruthProvider> make_full_provider();
/// `blender`: Blender Cycles, headless, with the settings of DESIGN §6.1.
[[nodiscard]] std::unique_ptr<TruthProvider> make_blender_provider();
/// `povray`: POV-Ray 3.7 from an SDL export (mesh2), with the settings of DESIGN §6.1.
[[nodiscard]] std::unique_ptr<TruthProvider> make_povray_provider();

}  // namespace sb::validation
