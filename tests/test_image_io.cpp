// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// tests/test_image_io.cpp — OpenEXR image files (lumx/render/image_io.h) and the pinhole camera (lumx/render/camera.h).
#include <lumx/core/diagnostic.h>
#include <lumx/render/image_io.h>
#include <lumx/render/camera.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace lumx;
using lumx_test::fresh_temp_dir;

TEST(ImageIo, FloatImageRoundTripsExactlyWithItsChannelOrder) {
  const auto dir = fresh_temp_dir("image_io_round_trip");
  render::Image image(7, 5, {"R", "G", "B"});
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = 1e-3f * float(x + 10 * y) + 1e5f * float(c);  // beyond half's range
  const std::string path = (dir / "a.exr").string();
  write_exr_image(path, image);
  const render::Image back = read_exr_image(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  ASSERT_EQ(back.channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(back.pixels, image.pixels);
}

TEST(ImageIo, HalfImageRoundsToHalfAndAOneChannelImageKeepsItsName) {
  const auto dir = fresh_temp_dir("image_io_half");
  render::Image image(3, 2, {"Y"});
  for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = 0.1f * float(i + 1);
  const std::string path = (dir / "y.exr").string();
  write_exr_image(path, image, /*half=*/true);
  const render::Image back = read_exr_image(path);
  ASSERT_EQ(back.channels, (std::vector<std::string>{"Y"}));
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    EXPECT_NEAR(back.pixels[i], image.pixels[i], image.pixels[i] * 0x1p-11) << i;  // half: 11-bit significand
}

TEST(ImageIo, LimitsAndBadFilesAreNamedErrors) {
  const auto dir = fresh_temp_dir("image_io_bad");
  render::Image image(64, 64, {"Y"}, 1.0f);
  const std::string path = (dir / "big.exr").string();
  write_exr_image(path, image);
  ImageReadLimits limits;
  limits.max_values = 64 * 64 - 1;
  try {
    read_exr_image(path, limits);
    FAIL() << "read beyond max_values";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ImageReadLimits::max_values"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("big.exr"), std::string::npos) << e.what();
  }
  const std::string junk = (dir / "junk.exr").string();
  std::ofstream(junk) << "not an OpenEXR file at all";
  EXPECT_THROW(read_exr_image(junk), Error);
  EXPECT_THROW(write_exr_image((dir / "empty.exr").string(), render::Image{}), Error);
}

TEST(PinholeCamera, ProjectInvertsRayAtEveryPixelCentre) {
  render::PinholeCamera cam;
  cam.position = {0.3, -1.2, 0.9};
  cam.look_at = {0.0, 0.5, 1.6};
  cam.width = 40;
  cam.height = 24;
  cam.vertical_fov_deg = 70;
  ASSERT_TRUE(cam.invalid_reason().empty());
  for (int y = 0; y < cam.height; y += 3)
    for (int x = 0; x < cam.width; x += 3) {
      const render::CameraRay r = cam.ray(x + 0.5, y + 0.5);
      double px = 0, py = 0;
      ASSERT_TRUE(cam.project(r.origin + 2.7 * r.direction, px, py));
      EXPECT_NEAR(px, x + 0.5, 1e-9);
      EXPECT_NEAR(py, y + 0.5, 1e-9);
    }
  // The image centre looks along the axis; the top row looks up (+Z here), the left column to the left.
  const glm::dvec3 axis = glm::normalize(cam.look_at - cam.position);
  EXPECT_NEAR(glm::dot(cam.ray(20, 12).direction, axis), 1.0, 1e-12);
  EXPECT_GT(cam.ray(20, 0).direction.z, cam.ray(20, 24).direction.z);
  double px = 0, py = 0;
  EXPECT_FALSE(cam.project(cam.position - axis, px, py));  // behind the eye
  render::PinholeCamera bad = cam;
  bad.up = axis;
  EXPECT_FALSE(bad.invalid_reason().empty());
}
