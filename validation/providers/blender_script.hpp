// The fixed part of the Python script the `blender` ground-truth provider runs inside Blender: it
// imports the glTF file, replaces lights, materials, world and camera by those of the in-memory
// scene (read from a PARAMS dictionary the provider writes above it) and renders one EXR per pass.
#pragma once

#include <string_view>

namespace sb::validation {

/// Python source that expects a global dictionary PARAMS (see validation/providers/blender.cpp for
/// its keys) and renders PARAMS["passes"] with Blender Cycles.
[[nodiscard]] std::string_view blender_script_body();

}  // namespace sb::validation
