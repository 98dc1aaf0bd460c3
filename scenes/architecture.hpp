// Architectural parts shared by the building scenes (atrium, temple, bistro): columns with bases
// and capitals, balusters, flights of steps, and a leaf cluster for potted plants.
#pragma once

#include <cstdint>

#include "scenes/primitives.hpp"

namespace sb::scenes {

/// Capital shapes of make_column.
enum class CapitalStyle {
  doric,  ///< echinus and square abacus
  ionic,  ///< echinus, abacus and a pair of spiral volutes on each face
  bell,   ///< a flared bell under a thick abacus (Romanesque cushion)
};

/// A column standing on y = 0, its axis on +Y.
struct ColumnSpec {
  float height = 4.0f;   ///< total: plinth, base, shaft and capital
  float radius = 0.28f;  ///< shaft radius at the bottom
  float taper = 0.86f;   ///< top radius over bottom radius
  int segments = 48;
  int rings = 12;        ///< shaft subdivisions along the height
  int flutes = 0;        ///< 0: plain shaft
  float flute_depth = 0.07f;
  bool plinth = true;
  CapitalStyle capital = CapitalStyle::doric;
  float uv_per_meter = 1.0f;
};

/// The column's mesh (plinth, moulded base, shaft, capital). The abacus top is at y = height and
/// its half-width is capital_half_width(spec).
[[nodiscard]] MeshData make_column(const ColumnSpec& spec);
[[nodiscard]] float capital_half_width(const ColumnSpec& spec);

/// A turned vase-shaped baluster standing on y = 0.
[[nodiscard]] MeshData make_baluster(float height, float radius, int segments);

/// A flight of `count` steps rising along -Z from z = 0: each `rise` high and `run` deep, `width`
/// wide and centred on x = 0; the top landing extends `landing` further.
[[nodiscard]] MeshData make_steps(int count, float width, float rise, float run, float landing, float uv_per_meter);

/// A cluster of `leaves` curved, tapered leaf blades on stems radiating from the origin upwards,
/// like a potted palm or fern; `size` is the blade length. Seeded.
[[nodiscard]] MeshData make_leaf_cluster(int leaves, float size, uint64_t seed, int segments = 6);

}  // namespace sb::scenes
