// JSON text with the suite's limits: nesting depth refused at the byte where it goes too deep,
// brackets inside strings not counted, and long arrays of objects parsed in linear time.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "renderer/io/json_text.hpp"

namespace sb::io {
namespace {

std::string nested(int levels) { return std::string(static_cast<size_t>(levels), '[') + std::string(static_cast<size_t>(levels), ']'); }

TEST(JsonText, NestingIsRefusedOnlyBeyondTheLimitAndNamesTheByte) {
  EXPECT_NO_THROW((void)parse_json(nested(kMaxJsonDepth)));
  try {
    (void)parse_json(" " + nested(kMaxJsonDepth + 1));
    FAIL() << "nesting deeper than the limit must be refused";
  } catch (const JsonTextError& e) {
    EXPECT_EQ(std::string(e.what()), "nesting deeper than 256 levels");
    EXPECT_EQ(e.byte(), static_cast<size_t>(kMaxJsonDepth) + 2);  // 1-based, after the leading space
  }
  // Brackets in strings, escaped quotes among them, are text.
  const std::string in_strings = "{\"a\": \"" + std::string(1000, '[') + "\\\"" + std::string(1000, '{') + "\"}";
  EXPECT_EQ(parse_json(in_strings).at("a").get<std::string>().size(), 2001u);
}

TEST(JsonText, ALongArrayOfObjectsParsesInLinearTime) {
  // 300,000 empty objects (1.5 MB): the parser's depth callback rescanned the array at the end of
  // every object, 35 s here; a million (a 4 MB glTF of empty nodes) ran for minutes. Linear, it
  // takes a fraction of a second; the bound leaves a slow machine 50 times that.
  std::string text = "[";
  for (int i = 0; i < 300000; ++i) text += i == 0 ? "{}" : ",{}";
  text += "]";
  const auto start = std::chrono::steady_clock::now();
  const nlohmann::json j = parse_json(text);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(j.size(), 300000u);
  EXPECT_LT(seconds, 10.0);
}

}  // namespace
}  // namespace sb::io
