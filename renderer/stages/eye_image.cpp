// Eye images with the standard AOV planes.
#include "renderer/stages/eye_image.hpp"

namespace sb {

Image make_eye_image(int width, int height, PlaneInit init) {
  Image image(width, height);
  for (std::string_view name : {planes::rgb, planes::depth, planes::normal, planes::albedo, planes::primid, planes::source})
    image.add_plane(name, init);
  return image;
}

EyeReader::EyeReader(const Image& image)
    : rgb_(image.data_f32(planes::rgb)),
      normal_(image.data_f32(planes::normal)),
      albedo_(image.data_f32(planes::albedo)),
      depth_(image.data_f32(planes::depth)),
      prim_(image.data_u32(planes::primid)),
      source_(image.data_u32(planes::source)) {}

EyeWriter::EyeWriter(Image& image)
    : rgb_(image.data_f32(planes::rgb)),
      normal_(image.data_f32(planes::normal)),
      albedo_(image.data_f32(planes::albedo)),
      depth_(image.data_f32(planes::depth)),
      prim_(image.data_u32(planes::primid)),
      source_(image.data_u32(planes::source)) {}

}  // namespace sb
