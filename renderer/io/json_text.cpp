#include "renderer/io/json_text.hpp"

#include <fmt/format.h>

namespace sb::io {

namespace {

/// nlohmann's message without its "[json.exception.KIND.ID] " prefix.
std::string without_prefix(const char* what) {
  const std::string_view s(what);
  if (s.rfind("[json.exception.", 0) == 0)
    if (const size_t end = s.find("] "); end != std::string_view::npos) return std::string(s.substr(end + 2));
  return std::string(s);
}

}  // namespace

nlohmann::json parse_json(std::string_view text) {
  using json = nlohmann::json;
  const json::parser_callback_t limit_depth = [](int depth, json::parse_event_t event, json&) {
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= kMaxJsonDepth)
      throw JsonTextError(fmt::format("nesting deeper than {} levels", kMaxJsonDepth), 0);
    return true;
  };
  try {
    return json::parse(text, limit_depth);
  } catch (const json::parse_error& e) {
    throw JsonTextError(without_prefix(e.what()), e.byte);
  } catch (const json::out_of_range& e) {
    // A number such as 1e400: nlohmann names it ("number overflow parsing '1e400'") but no byte.
    throw JsonTextError(without_prefix(e.what()), 0);
  }
}

}  // namespace sb::io
