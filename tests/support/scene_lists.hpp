// Names the parameterized tests iterate: registered pipelines and built-in or analytic scenes,
// and a test-name-safe form of them.
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer/pipeline.hpp"
#include "scenes/generators.hpp"

namespace sb::test {

inline std::vector<std::string> registered_pipelines() {
  std::vector<std::string> names;
  for (const Pipeline* p : pipelines()) names.push_back(p->info().name);
  return names;
}

inline std::vector<std::string> analytic_scenes() {
  std::vector<std::string> names;
  for (const scenes::GeneratorInfo& g : scenes::generators())
    if (g.analytic) names.push_back(g.name);
  return names;
}

inline std::vector<std::string> builtin_scenes() {
  std::vector<std::string> names;
  for (const scenes::GeneratorInfo& g : scenes::generators())
    if (g.builtin) names.push_back(g.name);
  return names;
}

/// "repro-rt" -> "repro_rt": pipeline and scene names as GoogleTest parameter names.
inline std::string param_name(const ::testing::TestParamInfo<std::string>& param) {
  std::string n = param.param;
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

}  // namespace sb::test
