// Image I/O through the OpenImageIO module (renderer/util/image_module.h): nothing of OpenImageIO is
// mapped until the first image is read or written, and every function the module carries writes
// what reads back. The course tone mapping and the error measures against values worked by hand.
#include <gtest/gtest.h>

#include <cmath>
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

// The course curve clamp((sqrt(2) v)^(1/2.2), 0, 1) * 255, truncated, worked by hand:
//   v = 0.5:   sqrt(2) v = 0.7071068, ln = -0.3465736, / 2.2 = -0.1575335, exp = 0.8542482, x 255 = 217.83 -> 217
//   v = 0.1:   0.1414214, ln = -1.9560115, / 2.2 = -0.8890961, exp = 0.4110271, x 255 = 104.81 -> 104
//   v = 0.001: 0.0014142, ln = -6.5611817, / 2.2 = -2.9823553, exp = 0.0506733, x 255 = 12.92 -> 12
//   v = 0.72:  1.0182338 > 1, clamped -> 255;   v <= 0 and NaN -> 0.
TEST(ToneMap, CourseCurveByHand) {
  EXPECT_EQ(tonemap_course(0.5f), 217);
  EXPECT_EQ(tonemap_course(0.1f), 104);
  EXPECT_EQ(tonemap_course(0.001f), 12);
  EXPECT_EQ(tonemap_course(0.72f), 255);
  EXPECT_EQ(tonemap_course(1000.0f), 255);
  EXPECT_EQ(tonemap_course(0.0f), 0);
  EXPECT_EQ(tonemap_course(-1.0f), 0);
  EXPECT_EQ(tonemap_course(NAN), 0);
}

// A written PNG holds those hand-worked levels, channel by channel.
TEST(ToneMap, PngHoldsTheHandWorkedLevels) {
  ImageRGB img;
  img.width = 2;
  img.height = 1;
  img.pixels = {Vec3(0.5f, 0.1f, 0.001f), Vec3(0.72f, 0.0f, -1.0f)};
  std::string path = test::temp_dir() + "/tonemap_by_hand.png";
  write_image(img, path);
  ImageRGB back = read_image(path);
  ASSERT_EQ(back.width, 2);
  const float levels[2][3] = {{217, 104, 12}, {255, 0, 0}};
  for (int i = 0; i < 2; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.pixels[i][c] * 255.0f, levels[i][c], 1e-3f) << i << " " << c;
}

// relative_mse = mean over pixels of (L - L_ref)^2 / (L_ref^2 + 0.01) on Rec. 709 luminance, worked
// by hand on two pixels:
//   red (1, 0, 0) against black: L = 0.2126, (0.2126)^2 / (0 + 0.01) = 0.04519876 / 0.01 = 4.519876
//   grey 0.3 against grey 0.1 (the weights sum to 1): (0.2)^2 / (0.01 + 0.01) = 2
//   mean (4.519876 + 2) / 2 = 3.259938. Swapped, the reference differs: 0.04519876 / 0.05519876 =
//   0.8188365 and 0.04 / 0.1 = 0.4, mean 0.6094183.
// rmse over the six channel differences (1, 0, 0, 0.2, 0.2, 0.2): sqrt(1.12 / 6) = 0.4320494.
TEST(ErrorMeasures, RelativeMseAndRmseByHand) {
  ImageRGB img, ref;
  img.width = ref.width = 2;
  img.height = ref.height = 1;
  img.pixels = {Vec3(1, 0, 0), Vec3(0.3f)};
  ref.pixels = {Vec3(0, 0, 0), Vec3(0.1f)};
  EXPECT_NEAR(relative_mse(img, ref), 3.259938, 1e-5);
  EXPECT_NEAR(relative_mse(ref, img), 0.6094183, 1e-5);
  EXPECT_NEAR(rmse(img, ref), 0.4320494, 1e-6);
  EXPECT_EQ(relative_mse(img, img), 0.0);
  ImageRGB other;
  other.width = 1;
  other.height = 1;
  other.pixels = {Vec3(1.0f)};
  EXPECT_TRUE(std::isinf(relative_mse(img, other))) << "sizes differ";
  EXPECT_TRUE(std::isinf(rmse(img, other))) << "sizes differ";
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
