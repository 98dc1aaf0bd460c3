// Small text helpers: parsing numbers given as text (command-line values, option strings), case,
// the current time as text.
#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <exception>
#include <optional>
#include <string>
#include <string_view>

namespace sb {

/// "1 thread", "2 threads": `n` and the noun, in the plural unless n is 1 (nouns that take an -s).
[[nodiscard]] inline std::string counted(long long n, std::string_view noun) {
  return std::to_string(n) + " " + std::string(noun) + (n == 1 ? "" : "s");
}

/// The whole of `text` as a finite decimal number, or nothing (partial parses, NaN, infinities,
/// hexadecimal such as 0x10 and leading blanks, which the C library would accept, fail).
[[nodiscard]] inline std::optional<double> parse_finite(const std::string& text) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text.front())) != 0) return std::nullopt;
  if (text.find_first_of("xX") != std::string::npos) return std::nullopt;
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

/// `text` with every occurrence of `from` (not empty) replaced by `to`, left to right (a replacement
/// is not searched again).
[[nodiscard]] inline std::string replace_all(std::string text, std::string_view from, std::string_view to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

/// `s` with ASCII letters in lower case (names, extensions, tokens compared without case).
[[nodiscard]] inline std::string lowercase(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

/// Whether `s` holds a control character (a line break, a tab, an escape, ...).
[[nodiscard]] inline bool has_control_character(std::string_view s) {
  return std::any_of(s.begin(), s.end(), [](char c) { return std::iscntrl(static_cast<unsigned char>(c)) != 0; });
}

/// `s` with each control character written as \n, \t, \r or \xHH, for one line of text (a
/// message, a comment in a generated script) that a newline in a name must not break.
[[nodiscard]] inline std::string printable(std::string_view s) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (std::iscntrl(u) == 0) {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15u];
    }
  }
  return out;
}

/// `word` as one word of a POSIX shell command line: as it is when it holds only characters no
/// shell treats specially (letters, digits and _-./=:,+@%), else in single quotes, a ' inside
/// written '\''; with `always`, quoted whatever it holds.
[[nodiscard]] inline std::string shell_quote(std::string_view word, bool always = false) {
  const bool plain = !always && !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
           std::string_view("_-./=:,+@%").find(c) != std::string_view::npos;
  });
  if (plain) return std::string(word);
  std::string out = "'";
  for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// The strftime form of a UTC time in every record, provenance and submission file the suite
/// writes: ISO 8601, "2026-11-21T20:00:00Z".
inline constexpr const char* kUtcTimeFormat = "%Y-%m-%dT%H:%M:%SZ";

/// The current UTC time formatted by strftime's `format` (kUtcTimeFormat unless given).
[[nodiscard]] inline std::string utc_now(const char* format = kUtcTimeFormat) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buf[64] = {};
  std::strftime(buf, sizeof buf, format, &tm);
  return buf;
}

}  // namespace sb
