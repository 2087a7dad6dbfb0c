// Image I/O through the OpenImageIO module (renderer/image_module.h): nothing of OpenImageIO is
// mapped until the first image is read or written, and every function the module carries writes
// what reads back.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "image.h"
#include "test_util.h"

namespace pt {
namespace {

bool openimageio_mapped() {
  std::ifstream maps("/proc/self/maps");
  std::string text((std::istreambuf_iterator<char>(maps)), std::istreambuf_iterator<char>());
  EXPECT_FALSE(text.empty());
  return text.find("libOpenImageIO") != std::string::npos;
}

ImageRGB ramp(int w, int h) {
  ImageRGB img;
  img.width = w;
  img.height = h;
  img.pixels.resize(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = Vec3(0.1f * x, 0.05f * y, 0.25f + 0.01f * (x + y));
  return img;
}

// First in the file: ctest runs each test in its own process, and so does this file's order when
// run whole, so nothing has touched an image yet.
TEST(ImageModule, NotLoadedUntilTheFirstImage) {
  ASSERT_FALSE(openimageio_mapped()) << "OpenImageIO is linked in again: every process pays ~0.4 s to start";
  std::string png = encode_png8(std::vector<uint8_t>(4 * 2 * 3, 200), 4, 2);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_TRUE(openimageio_mapped());
}

TEST(ImageModule, ExrKeepsPixelsOnDiskAndInMemory) {
  ImageRGB img = ramp(7, 5);
  std::string path = test::temp_dir() + "/module_roundtrip.exr";
  write_image(img, path, {{"pathtracer:seed", "42"}});
  ImageRGB back = read_image(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(back.pixels[i][c], img.pixels[i][c]) << "pixel " << i;

  // The same image encoded in memory decodes to the same pixels.
  std::string bytes = encode_exr(img, {});
  std::string mem_path = test::temp_dir() + "/module_memory.exr";
  std::ofstream(mem_path, std::ios::binary) << bytes;
  ImageRGB mem = read_image(mem_path);
  ASSERT_EQ(mem.pixels.size(), img.pixels.size());
  for (size_t i = 0; i < img.pixels.size(); ++i) EXPECT_FLOAT_EQ(mem.pixels[i].y, img.pixels[i].y);
}

TEST(ImageModule, PngHoldsTheCourseToneMapping) {
  ImageRGB img = ramp(6, 3);
  std::string path = test::temp_dir() + "/module_roundtrip.png";
  write_image(img, path);
  ImageRGB back = read_image(path);  // 8-bit values read back as v / 255
  ASSERT_EQ(back.width, 6);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(back.pixels[i][c] * 255.0f, float(tonemap_course(img.pixels[i][c])), 1e-3f) << "pixel " << i;

  std::vector<uint8_t> rgb(6 * 3 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 13);
  write_png8(rgb, 6, 3, path);
  back = read_image(path);
  for (size_t i = 0; i < back.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.pixels[i][c] * 255.0f, float(rgb[3 * i + c]), 1e-3f);
}

TEST(ImageModule, UnknownFormatAndUnreadableFileAreNamed) {
  std::string bad = test::temp_dir() + "/module.notaformat";
  try {
    write_image(ramp(2, 2), bad);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  try {
    read_image(test::temp_dir() + "/no_such_image.exr");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_image.exr"), std::string::npos) << e.what();
  }
}

TEST(ImageModule, RequireFindsTheBuiltModule) { EXPECT_NO_THROW(require_image_io()); }

}  // namespace
}  // namespace pt
