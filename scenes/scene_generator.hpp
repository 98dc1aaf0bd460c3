// The interface between the generator registry (generators.cpp) and the one-file-per-scene
// generators: each scene file defines one `<name>_generator()` returning its entry.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "renderer/math.hpp"
#include "scenes/generators.hpp"
#include "scenes/gltf_builder.hpp"

namespace sb::scenes {

/// What a generator's build function gets: the seed and the parameters, already checked against
/// the generator's ranges, with the defaults filled in.
struct GeneratorContext {
  uint64_t seed = 1;
  std::map<std::string, double> params;

  /// The value of a declared parameter (std::logic_error for an undeclared one: a generator bug).
  [[nodiscard]] double param(const std::string& name) const;
  [[nodiscard]] int int_param(const std::string& name) const;
};

/// A registered generator: its description and the function that fills the builder.
struct GeneratorEntry {
  GeneratorInfo info;
  void (*build)(const GeneratorContext& context, GltfBuilder& builder) = nullptr;
};

/// The default view of a scene: the camera at `eye` looking at `target` (the main subject, whose
/// distance becomes the convergence distance unless `convergence` > 0), 1920x1080, 40° vertical
/// field of view, interaxial 0.064 m.
struct DefaultView {
  vec3 eye{0.0f};
  vec3 target{0.0f, 0.0f, -1.0f};
  double convergence = 0.0;
  double yfov_degrees = 40.0;
  double znear = 0.05;
  double zfar = 1000.0;
};
/// Writes the default camera and rig (see DefaultView) into the builder.
void set_default_view(GltfBuilder& builder, const DefaultView& view);

// The generators, in registry order.
GeneratorEntry spheres_generator();
GeneratorEntry atrium_generator();
GeneratorEntry bistro_generator();
GeneratorEntry temple_generator();
GeneratorEntry dragon_generator();
GeneratorEntry complexity_generator();
GeneratorEntry lit_plane_generator();
GeneratorEntry box_wall_generator();
GeneratorEntry thin_pole_generator();
GeneratorEntry textured_plane_generator();
GeneratorEntry slanted_plane_generator();
GeneratorEntry fence_generator();

}  // namespace sb::scenes
