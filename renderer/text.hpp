// Parsing of numbers given as text (command-line values, option strings).
#pragma once

#include <cmath>
#include <exception>
#include <optional>
#include <string>

namespace sb {

/// The whole of `text` as a finite number, or nothing (partial parses, NaN and infinities fail).
[[nodiscard]] inline std::optional<double> parse_finite(const std::string& text) {
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace sb
