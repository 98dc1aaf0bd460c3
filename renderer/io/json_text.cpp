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

/// Refuses nesting deeper than kMaxJsonDepth, naming the byte where it goes deeper, in one pass
/// over the text (brackets inside strings do not count). The parser's own callback could do it,
/// but nlohmann's callback parser scans each finished container's parent again: quadratic in the
/// length of an array of objects (a million nodes took minutes).
void require_shallow(std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // the escaped character
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw JsonTextError(fmt::format("nesting deeper than {} levels", kMaxJsonDepth), i + 1);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

}  // namespace

nlohmann::json parse_json(std::string_view text) {
  using json = nlohmann::json;
  require_shallow(text);
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    throw JsonTextError(without_prefix(e.what()), e.byte);
  } catch (const json::out_of_range& e) {
    // A number such as 1e400: nlohmann names it ("number overflow parsing '1e400'") but no byte.
    throw JsonTextError(without_prefix(e.what()), 0);
  }
}

}  // namespace sb::io
