// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx render room`: a baked bundle in, valid EXR and PNG pictures and a parsable table out, the same for one
// and two threads; located errors for a luminaire outside the room and a bundle without geometry.
#include "cli_test_support.h"
#include "luminaire_test_scenes.h"
#include "test_support.h"

#include <lumx/render/image_io.h>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace {

using namespace lumx_test;
namespace fs = std::filesystem;

std::string read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

/// Width and height from a PNG's IHDR chunk; {0, 0} when the signature or the chunk is wrong.
std::pair<unsigned, unsigned> png_size(const fs::path& p) {
  const std::string b = read_bytes(p);
  if (b.size() < 24 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || b.compare(12, 4, "IHDR") != 0) return {0, 0};
  auto be32 = [&](std::size_t i) {
    return (unsigned(std::uint8_t(b[i])) << 24) | (unsigned(std::uint8_t(b[i + 1])) << 16) |
           (unsigned(std::uint8_t(b[i + 2])) << 8) | unsigned(std::uint8_t(b[i + 3]));
  };
  return {be32(16), be32(20)};
}

/// A small baked bundle (the sphere luminaire, levels 1 and 8), made once per process.
const fs::path& baked_bundle() {
  static const fs::path bundle = [] {
    const fs::path dir = fresh_temp_dir("lumx_cli_render_room");
    const fs::path glb = write_sphere_luminaire(dir);
    const CliRun r = run_cli("bake " + quoted(glb) + " " + quoted(dir / "sphere.lumx") +
                             " --particles 30000 --levels 1 8 --no-eval --volume-voxels 0");
    EXPECT_EQ(r.status, 0) << r.out;
    return dir / "sphere.lumx";
  }();
  return bundle;
}

TEST(CliRenderRoom, PicturesAndTableAreValidAndTheSameForOneAndTwoThreads) {
  const fs::path out = fresh_temp_dir("lumx_cli_render_room_out");
  const std::string common = "render room " + quoted(baked_bundle()) + " --particles 20000 --size 96 64 " +
                             "--occluder 1.2 1.2 0.7 1.8 1.8 0.75 --json ";
  const CliRun one = run_cli(common + "-o " + quoted(out / "t1") + " --threads 1", false);
  ASSERT_EQ(one.status, 0) << one.out;
  const CliRun two = run_cli(common + "-o " + quoted(out / "t2") + " --threads 2", false);
  ASSERT_EQ(two.status, 0) << two.out;

  const nlohmann::json j = nlohmann::json::parse(one.out);
  EXPECT_EQ(j.at("reference").at("particles").get<int>(), 20000);
  const auto& methods = j.at("methods");
  std::vector<std::string> names;
  for (const auto& m : methods) names.push_back(m.at("name").get<std::string>());
  EXPECT_EQ(names, (std::vector<std::string>{"reference", "apl-1", "apl-8", "lod", "far-field"}));
  EXPECT_EQ(nlohmann::json::parse(read_bytes(out / "t1" / "room_table.json")).at("methods").size(), 5u);
  const nlohmann::json j2 = nlohmann::json::parse(two.out);
  for (std::size_t i = 0; i < methods.size(); ++i) {
    const double e = methods[i].at("relative_rmse").get<double>();
    EXPECT_TRUE(std::isfinite(e) && e >= 0.0);
    EXPECT_EQ(e, j2.at("methods")[i].at("relative_rmse").get<double>()) << names[i];  // threads change nothing
  }
  EXPECT_EQ(j.at("reference").at("noise_relative_rmse").get<double>(),
            j2.at("reference").at("noise_relative_rmse").get<double>());

  for (const std::string& name : names) {
    const lumx::render::Image a = lumx::read_exr_image((out / "t1" / ("room_" + name + ".exr")).string());
    const lumx::render::Image b = lumx::read_exr_image((out / "t2" / ("room_" + name + ".exr")).string());
    EXPECT_EQ(a.width, 96);
    EXPECT_EQ(a.height, 64);
    ASSERT_GE(a.channel_index("Y"), 0);
    ASSERT_GE(a.channel_index("E"), 0);
    EXPECT_EQ(a.pixels, b.pixels) << name;
    double sum = 0;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const float l = a.at(x, y, a.channel_index("Y")), e = a.at(x, y, a.channel_index("E"));
        EXPECT_NEAR(l, 0.5 / lumx::kPi * e, 1e-6 * e + 1e-9);  // L = ρE/π with the default ρ = 0.5
        sum += l;
      }
    EXPECT_GT(sum, 0.0) << name;
    const auto size = png_size(out / "t1" / ("room_" + name + ".png"));
    EXPECT_EQ(size.first, 96u) << name;
    EXPECT_GT(size.second, 64u) << name;  // picture plus the heading
    if (name != "reference") {
      EXPECT_GT(png_size(out / "t1" / ("room_" + name + "_difference.png")).first, 96u);
    }
  }
  EXPECT_GT(png_size(out / "t1" / "room_comparison.png").first, 3 * 96u);
}

TEST(CliRenderRoom, LocatedErrors) {
  const fs::path out = fresh_temp_dir("lumx_cli_render_room_bad");
  const CliRun outside = run_cli("render room " + quoted(baked_bundle()) + " -o " + quoted(out / "a") +
                                 " --particles 2000 --luminaire-at 5 1 1");
  EXPECT_EQ(outside.status, 1) << outside.out;
  EXPECT_NE(outside.out.find("not inside the room"), std::string::npos) << outside.out;
  // A bundle converted from photometry has no geometry: the reference cannot be traced.
  const CliRun convert = run_cli("convert " + quoted(fs::path(LUMX_SOURCE_DIR) / "samples" / "downlight.ies") + " " +
                                 quoted(out / "downlight.lumx"));
  ASSERT_EQ(convert.status, 0) << convert.out;
  const CliRun no_geometry =
      run_cli("render room " + quoted(out / "downlight.lumx") + " -o " + quoted(out / "b") + " --particles 2000");
  EXPECT_EQ(no_geometry.status, 1) << no_geometry.out;
  EXPECT_NE(no_geometry.out.find("no luminaire geometry"), std::string::npos) << no_geometry.out;
}

}  // namespace
