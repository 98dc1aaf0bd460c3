// Registry of the procedural scene generators.
#include "scenes/generators.hpp"

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb::scenes {

const std::vector<GeneratorInfo>& generators() {
  static const std::vector<GeneratorInfo> list;
  return list;
}

const GeneratorInfo& find_generator(const std::string& name) {
  for (const GeneratorInfo& g : generators())
    if (g.name == name) return g;
  throw InputError(fmt::format("unknown scene generator '{}'", name));
}

GenerateResult generate(const std::string& name, const GenerateOptions&, const std::filesystem::path&) {
  (void)find_generator(name);
  return {};
}

}  // namespace sb::scenes
