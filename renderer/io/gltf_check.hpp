// Structural check of a glTF 2.0 JSON document before it is loaded: every field the suite reads is
// checked for type and range, every cross-reference for bounds, and the first fault is reported
// with its JSON pointer (e.g. "/accessors/3/count").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace sb::io {

/// The glTF extensions the loader reads, in the order messages list them.
[[nodiscard]] const std::vector<std::string>& supported_gltf_extensions();

/// Throws InputError "<file>: <json pointer>: <what is wrong>; <what to do>" at the first fault.
/// An extension the file requires and the loader does not read is that fault before any other:
/// it changes what the rest of the document means (compressed geometry, for one).
void check_gltf_json(const nlohmann::json& doc, const std::string& file);

}  // namespace sb::io
