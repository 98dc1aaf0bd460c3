// JSON text from files the suite reads (glTF, results lines, baselines, provenance, markers),
// parsed with the limits that keep bad input an input error: no nesting deeper than
// kMaxJsonDepth (later recursive consumers, such as the glTF loader, would exhaust the stack)
// and no number beyond a double's range.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace sb::io {

/// Nesting deeper than this is refused; real glTF and results records stay below 20.
inline constexpr int kMaxJsonDepth = 256;

/// Why a JSON text was refused: what() says what is wrong and, where known, at which byte.
class JsonTextError : public std::runtime_error {
 public:
  JsonTextError(const std::string& what, size_t byte) : std::runtime_error(what), byte_(byte) {}
  /// The byte offset (1-based) the parser stopped at; 0 when the parser does not say.
  [[nodiscard]] size_t byte() const { return byte_; }

 private:
  size_t byte_;
};

/// Parses `text` as one JSON value; JsonTextError on a syntax error, a number that overflows a
/// double, or nesting deeper than kMaxJsonDepth.
[[nodiscard]] nlohmann::json parse_json(std::string_view text);

/// Whether `text` is well-formed UTF-8 (what JSON text can hold as it is).
[[nodiscard]] inline bool is_utf8(const std::string& text) {
  try {
    (void)nlohmann::json(text).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

/// `value` as JSON text (`indent` as nlohmann's dump), with bytes that are not UTF-8 (a file name
/// of another encoding, given on the command line) written as U+FFFD instead of throwing.
[[nodiscard]] inline std::string json_text(const nlohmann::json& value, int indent = -1) {
  return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace sb::io
