// Tests of the image buffers: plane shapes, lookup errors, typed access and Source tag names.
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <optional>
#include <string>

#include "renderer/error.hpp"
#include "renderer/image.hpp"

namespace sb {
namespace {

TEST(ImageTest, StandardPlanesHaveTheirFixedShapes) {
  Image image(4, 3);
  EXPECT_EQ(image.add_plane(planes::rgb).channels(), 3);
  EXPECT_EQ(image.add_plane(planes::depth).channels(), 1);
  EXPECT_EQ(image.add_plane(planes::normal).type(), PlaneType::f32);
  const Plane& primid = image.add_plane(planes::primid);
  EXPECT_EQ(primid.type(), PlaneType::u32);
  for (const uint32_t id : primid.u32()) EXPECT_EQ(id, kNoPrimitive);
  for (const uint32_t tag : image.add_plane(planes::source).u32()) EXPECT_EQ(tag, static_cast<uint32_t>(Source::hole));
  EXPECT_EQ(image.plane(planes::rgb).value_count(), 4u * 3u * 3u);
  EXPECT_THROW(image.add_plane(planes::albedo, 4, PlaneType::f32), InputError);
  EXPECT_THROW(image.add_plane(planes::albedo, 3, PlaneType::u32), InputError);
  EXPECT_THROW(image.add_plane(planes::rgb), InputError);  // already present
  EXPECT_THROW(image.add_plane("Motion", 2, PlaneType::f32), InputError);
  EXPECT_THROW(image.add_plane("mo.tion", 2, PlaneType::f32), InputError);
  EXPECT_THROW(image.add_plane("left", 3, PlaneType::f32), InputError);  // an EXR eye layer name
  EXPECT_THROW(image.add_plane("not_standard"), InputError);
  EXPECT_THROW(Image(-1, 2), InputError);
  EXPECT_THROW(Image(kMaxImageDimension + 1, 2), InputError);
}

TEST(ImageTest, UnsetPlanesHaveTheirShapeAndTakeWrites) {
  Image image(5, 4);
  Plane& rgb = image.add_plane(planes::rgb, PlaneInit::unset);
  Plane& primid = image.add_plane(planes::primid, PlaneInit::unset);
  EXPECT_EQ(rgb.value_count(), 5u * 4u * 3u);
  EXPECT_EQ(primid.value_count(), 5u * 4u);
  rgb.fill(0.25f);
  primid.fill(7u);
  EXPECT_EQ(image.rgb_at(4, 3)[2], 0.25f);
  EXPECT_EQ(primid.at_u32(4, 3), 7u);
  // Filled is still the default.
  for (const float v : image.add_plane(planes::depth).f32()) EXPECT_EQ(v, 0.0f);
  EXPECT_THROW(image.add_plane(planes::albedo, 4, PlaneType::f32, PlaneInit::unset), InputError);
}

TEST(ImageTest, MissingPlaneErrorNamesItAndListsThePresentOnes) {
  Image image(2, 2);
  image.add_plane(planes::rgb);
  image.add_plane(planes::depth);
  try {
    (void)image.plane(planes::albedo);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'albedo'"), std::string::npos) << message;
    EXPECT_NE(message.find("rgb, depth"), std::string::npos) << message;
  }
  EXPECT_TRUE(image.has_plane(planes::depth));
  EXPECT_FALSE(image.has_plane(planes::albedo));
  EXPECT_EQ(image.find_plane(planes::albedo), nullptr);
}

TEST(ImageTest, TypedAccessChecksTheSampleType) {
  Image image(3, 2);
  Plane& rgb = image.add_plane(planes::rgb);
  EXPECT_THROW((void)rgb.data_u32(), InputError);
  EXPECT_THROW((void)image.data_u32(planes::rgb), InputError);
  EXPECT_THROW(image.add_plane(planes::primid).fill(1.0f), InputError);

  image.set_rgb(2, 1, {1.0f, 2.0f, 3.0f});
  EXPECT_EQ(image.rgb_at(2, 1), (std::array<float, 3>{1.0f, 2.0f, 3.0f}));
  const Plane& same = image.plane(planes::rgb);
  EXPECT_EQ(same.at_f32(2, 1, 1), 2.0f);
  EXPECT_EQ(same.offset(2, 1), (1u * 3u + 2u) * 3u);
  EXPECT_EQ(image.data_f32(planes::rgb)[same.offset(2, 1) + 2], 3.0f);
  EXPECT_TRUE(image.contains(2, 1));
  EXPECT_FALSE(image.contains(3, 1));
  EXPECT_FALSE(image.contains(0, -1));
}

TEST(ImageTest, EqualityIsBitwise) {
  Image a(2, 1);
  a.add_plane(planes::depth).fill(std::numeric_limits<float>::quiet_NaN());
  Image b = a;
  EXPECT_TRUE(a == b);  // NaN samples with the same bits compare equal
  b.plane(planes::depth).at_f32(1, 0) = -0.0f;
  EXPECT_FALSE(a == b);
  EXPECT_TRUE(b.remove_plane(planes::depth));
  EXPECT_FALSE(b.remove_plane(planes::depth));
  EXPECT_EQ(b.plane_list(), "");
}

TEST(ImageTest, SourceTagsHaveStableNames) {
  for (std::size_t i = 0; i < kSourceCount; ++i) {
    const auto tag = static_cast<Source>(i);
    EXPECT_EQ(parse_source(to_string(tag)), tag);
    EXPECT_EQ(source_from_u32(static_cast<uint32_t>(i)), tag);
  }
  EXPECT_EQ(to_string(Source::reshaded_traced), "reshaded_traced");
  EXPECT_EQ(to_string(Source::hole), "hole");
  EXPECT_EQ(source_from_u32(static_cast<uint32_t>(kSourceCount)), std::nullopt);
  try {
    (void)parse_source("warped");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'warped'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("inpainted"), std::string::npos);
  }
}

}  // namespace
}  // namespace sb
