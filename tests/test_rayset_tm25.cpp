// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The TM-25 writer: write-then-read is exact (the rays' bits, the header), writing is atomic, values TM-25
// cannot hold are refused; and rays stream in bounded memory (a 2 M-ray file written and read with peak
// RSS growth far below its size), with the read speed on the largest real file reported.
#include "memory_test_support.h"
#include "rayset_test_support.h"

#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include <malloc.h>

using namespace lumx;
using namespace lumx_rays;

namespace {

bool same_info(const RaysetInfo& a, const RaysetInfo& b) {
  // TM-25 states the totals as float32: compared as floats (a text file's double becomes its float).
  const auto same = [](double x, double y) {
    return static_cast<float>(x) == static_cast<float>(y) || (std::isnan(x) && std::isnan(y));
  };
  if (a.quantity != b.quantity || !same(a.header_flux, b.header_flux) || a.ray_count != b.ray_count) return false;
  if (a.wavelength_nm.has_value() != b.wavelength_nm.has_value()) return false;
  if (a.wavelength_nm && *a.wavelength_nm != *b.wavelength_nm) return false;
  if (a.spectra.size() != b.spectra.size()) return false;
  for (std::size_t i = 0; i < a.spectra.size(); ++i)
    if (!same_bits(a.spectra[i].wavelength_nm, b.spectra[i].wavelength_nm) ||
        !same_bits(a.spectra[i].weight, b.spectra[i].weight))
      return false;
  return true;
}

/// Units in the last place between two floats of the same sign.
std::int64_t ulps(float a, float b) {
  std::int32_t ia, ib;
  std::memcpy(&ia, &a, 4);
  std::memcpy(&ib, &b, 4);
  return std::abs(static_cast<std::int64_t>(ia) - ib);
}

}  // namespace

TEST(RaysetTm25Write, RealFilesWriteThenReadAreBitExact) {
  const auto files = real_ray_files();
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const fs::path d = scratch("tm25_roundtrip");
  int tested = 0;
  for (const auto& f : files) {
    auto src = open_rayset(f.string());
    const RaysetInfo& info = src->info();
    SCOPED_TRACE(f.filename().string());
    const bool mm = info.source_length_unit == "mm";
    const RayChunk original = read_all_rays(*src, 1000000);
    const fs::path a = d / "a.tm25ray", b = d / "b.tm25ray";
    write_tm25(a.string(), info, *src);
    auto back = open_rayset(a.string());
    const RayChunk again = read_all_rays(*back, 1000000);
    EXPECT_TRUE(same_info(info, back->info()));
    if (mm) {
      // Every position read from a file in mm has a float in mm that reads back as exactly it.
      EXPECT_TRUE(same_rays(original, again));
    } else {
      // Metre floats from other units: within 1 ulp (docs/rays.md: mm floats cannot hold every metre float).
      ASSERT_EQ(original.size(), again.size());
      for (std::size_t i = 0; i < original.size(); ++i) {
        EXPECT_LE(ulps(original.x[i], again.x[i]), 1);
        EXPECT_LE(ulps(original.y[i], again.y[i]), 1);
      }
      EXPECT_TRUE(same_bits(original.flux, again.flux));
      EXPECT_TRUE(same_bits(original.dx, again.dx));
    }
    if (info.format == "TM-25") {
      EXPECT_EQ(info.text, back->info().text);
      for (const char* k : {"creation method", "ray start position", "spectral identifier", "wavelength min nm",
                            "wavelength max nm", "luminous flux lm", "radiant flux W", "single wavelength nm"}) {
        const double x = info.values.at(k), y = back->info().values.at(k);
        EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << k << ": " << x << " vs " << y;
      }
      // The copy's ray floats against the original's: identical, except positions where mm floats are
      // not one-to-one with metre floats (mantissas just above a power of two: two mm floats read as the
      // same metre float, about 1.2 % of positions); those differ by 1 ulp in mm. Directions and fluxes
      // are identical (already unit vectors to 1e-6).
      const std::string fa = read_bytes(f), fb = read_bytes(a);
      const std::uint64_t n = info.ray_count;
      const auto cols = static_cast<std::size_t>(info.values.at("columns"));
      const auto off_a = static_cast<std::size_t>(info.values.at("ray data offset"));
      const auto off_b = static_cast<std::size_t>(back->info().values.at("ray data offset"));
      std::size_t differing = 0, records = 0;
      if (cols == 7) {
        for (std::size_t i = 0; i < n; ++i) {
          const char* ra = fa.data() + off_a + i * 28;
          const char* rb = fb.data() + off_b + i * 28;
          records += std::memcmp(ra, rb, 28) == 0;
          EXPECT_EQ(std::memcmp(ra + 12, rb + 12, 16), 0) << "ray " << i;
          for (int k = 0; k < 3; ++k) {
            float x, y;
            std::memcpy(&x, ra + 4 * k, 4);
            std::memcpy(&y, rb + 4 * k, 4);
            differing += x != y;
            EXPECT_LE(ulps(x, y), 1);
          }
        }
        EXPECT_LT(static_cast<double>(differing), 0.03 * 3 * static_cast<double>(n));
        std::printf("  %-60s copy: %llu of %llu records byte-identical, %.2f %% of positions 1 ulp off\n",
                    f.filename().string().c_str(), static_cast<unsigned long long>(records),
                    static_cast<unsigned long long>(n), 100.0 * static_cast<double>(differing) / (3.0 * n));
      }
    }
    // Written once, a file writes back byte for byte.
    write_tm25(b.string(), back->info(), *back);
    EXPECT_EQ(read_bytes(a), read_bytes(b));
    ++tested;
  }
  EXPECT_GE(tested, 13);
  fs::remove_all(d);
}

TEST(RaysetTm25Write, SyntheticHeaderAndRaysSurviveExactly) {
  const fs::path d = scratch("tm25_synth");
  RaysetInfo info;
  info.file = "synthetic";
  info.quantity = PhotometricQuantity::radiometric;
  info.header_flux = 2.5;
  info.text["name"] = "Ωmega lamp — grün";
  info.text["manufacturer"] = std::string(1000, 'M');  // the full 1000 characters, no terminator
  info.text["data reference"] = "doi:10/xyz";
  info.text["creation date"] = "2026-11-22T01:02:03Z";
  info.text["additional text"] = "line one\nline two ✓";
  info.values["luminous flux lm"] = 800;
  info.values["creation method"] = 1;
  info.values["ray start position"] = 3;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-0.05f, 0.05f), dir(-1, 1), flux(0, 1), lam(380, 780);
  RayChunk rays;
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 k(dir(rng), dir(rng), dir(rng));
    if (glm::length(k) < 1e-3f) k = {0, 0, 1};
    rays.push_back({pos(rng), pos(rng), pos(rng)}, glm::normalize(k), flux(rng));
    rays.wavelength_nm.push_back(lam(rng));
  }
  MemoryRaySource mem(rays, info);
  const fs::path a = d / "s.tm25ray";
  write_tm25(a.string(), info, mem);
  std::vector<Diagnostic> w;
  auto back = open_collect(a, w);
  const RaysetInfo& r = back->info();
  EXPECT_EQ(r.text.at("name"), info.text.at("name"));
  EXPECT_EQ(r.text.at("manufacturer"), info.text.at("manufacturer"));
  EXPECT_EQ(r.text.at("data reference"), "doi:10/xyz");
  EXPECT_EQ(r.text.at("creation date"), "2026-11-22T01:02:03Z");
  EXPECT_EQ(r.text.at("additional text"), info.text.at("additional text"));
  EXPECT_EQ(r.quantity, PhotometricQuantity::radiometric);
  EXPECT_EQ(r.header_flux, 2.5);
  EXPECT_EQ(r.values.at("luminous flux lm"), 800);
  EXPECT_EQ(r.values.at("creation method"), 1);
  EXPECT_EQ(r.values.at("ray start position"), 3);
  EXPECT_EQ(r.values.at("spectral identifier"), 2);  // wavelength per ray
  const RayChunk c = read_all_rays(*back, 100000);
  ASSERT_EQ(c.size(), rays.size());
  EXPECT_TRUE(same_bits(c.dx, rays.dx) && same_bits(c.dy, rays.dy) && same_bits(c.dz, rays.dz));
  EXPECT_TRUE(same_bits(c.flux, rays.flux));
  EXPECT_TRUE(same_bits(c.wavelength_nm, rays.wavelength_nm));
  EXPECT_EQ(r.values.at("wavelength min nm"), *std::min_element(rays.wavelength_nm.begin(), rays.wavelength_nm.end()));
  // Arbitrary metre floats: most come back exactly, every one within 1 ulp (docs/rays.md).
  std::size_t exact = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    for (auto [p, q] : {std::pair{c.x[i], rays.x[i]}, {c.y[i], rays.y[i]}, {c.z[i], rays.z[i]}}) {
      EXPECT_LE(ulps(p, q), 1);
      exact += p == q;
    }
  }
  EXPECT_GT(static_cast<double>(exact), 0.95 * 3 * static_cast<double>(c.size()));
  std::printf("  arbitrary metre floats written and read back exactly: %.2f %%\n",
              100.0 * static_cast<double>(exact) / (3.0 * static_cast<double>(c.size())));
  // Rays read from the file round-trip exactly.
  const fs::path b = d / "t.tm25ray";
  write_tm25(b.string(), r, *back);
  EXPECT_EQ(read_bytes(a), read_bytes(b));
  // The 20000 rays do not sum to 2.5 W: the one flux warning, nothing else.
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].field, "total radiant flux (4.7.1.5)");

  // A single wavelength and one spectral table (identifier 3), photometric.
  RaysetInfo p;
  p.quantity = PhotometricQuantity::photometric;
  p.header_flux = NAN;
  p.spectra.push_back({{400, 500, 600}, {0.5f, 1, 0.25f}});
  RayChunk few;
  few.push_back({0, 0, 0}, {0, 0, 1}, 1);
  MemoryRaySource mem2(few, p);
  write_tm25(a.string(), p, mem2);
  auto back2 = open_rayset(a.string());
  EXPECT_EQ(back2->info().values.at("spectral identifier"), 3);
  ASSERT_EQ(back2->info().spectra.size(), 1u);
  EXPECT_TRUE(same_bits(back2->info().spectra[0].weight, p.spectra[0].weight));
  EXPECT_EQ(back2->info().values.at("wavelength min nm"), 400);
  EXPECT_TRUE(std::isnan(back2->info().header_flux));
  p.spectra.clear();
  p.wavelength_nm = 555;
  MemoryRaySource mem3(few, p);
  write_tm25(a.string(), p, mem3);
  auto back3 = open_rayset(a.string());
  EXPECT_EQ(back3->info().values.at("spectral identifier"), 1);
  EXPECT_EQ(back3->info().wavelength_nm, 555.0);
  fs::remove_all(d);
}

TEST(RaysetTm25Write, FailureLeavesTheTargetUntouched) {
  const fs::path d = scratch("tm25_atomic");
  const fs::path target = d / "out.tm25ray";
  write_bytes(target, "old contents");
  RaysetInfo info;
  info.quantity = PhotometricQuantity::photometric;
  RayChunk rays;
  for (int i = 0; i < 100; ++i) rays.push_back({0, 0, 0}, {0, 0, 1}, 1);
  rays.dx[57] = NAN;
  MemoryRaySource bad(rays, info);
  try {
    write_tm25(target.string(), info, bad);
    ADD_FAILURE() << "wrote";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().file, target.string());
    EXPECT_EQ(e.diagnostic().field, "ray direction");
    EXPECT_NE(e.diagnostic().message.find("ray 58"), std::string::npos) << e.what();
  }
  // A reader failing in the middle of the source: its own located error comes through.
  Tm25Spec spec;
  spec.rows.assign(1000, {1, 2, 3, 0, 0, 1, 1});
  spec.rows[600][6] = -1;  // negative flux
  write_bytes(d / "src.tm25ray", build_tm25(spec));
  auto src = open_rayset((d / "src.tm25ray").string());
  try {
    write_tm25(target.string(), src->info(), *src);
    ADD_FAILURE() << "wrote";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().file, (d / "src.tm25ray").string());
    EXPECT_EQ(e.diagnostic().byte_offset, 36288 + 600 * 28 + 24);
  }
  EXPECT_EQ(read_bytes(target), "old contents");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(d)) files += e.is_regular_file();
  EXPECT_EQ(files, 2u);  // out.tm25ray and src.tm25ray: no temporary left behind
  EXPECT_THROW(write_tm25((d / "missing" / "x.tm25ray").string(), info, bad), Error);
  fs::remove_all(d);
}

TEST(RaysetTm25Write, RefusesWhatTm25CannotHold) {
  const fs::path d = scratch("tm25_refuse");
  const std::string out = (d / "x.tm25ray").string();
  RayChunk one;
  one.push_back({0, 0, 0}, {0, 0, 1}, 1);
  const auto field_of = [&](RaysetInfo info, RayChunk rays) {
    MemoryRaySource src(rays, info);
    try {
      write_tm25(out, info, src);
    } catch (const Error& e) {
      return e.diagnostic().field;
    }
    return std::string("(written)");
  };
  RaysetInfo ok;
  EXPECT_EQ(field_of(ok, one), "(written)");
  RayChunk lam = one;
  lam.wavelength_nm = {550};
  EXPECT_EQ(field_of(ok, lam), "wavelength");  // per-ray wavelengths need radiant flux
  RaysetInfo two = ok;
  two.spectra = {{{500}, {1}}, {{600}, {1}}};
  EXPECT_EQ(field_of(two, one), "spectral tables");
  RaysetInfo long_text = ok;
  long_text.text["camera"] = std::string(1001, 'c');
  EXPECT_EQ(field_of(long_text, one), "camera");
  RaysetInfo bad_utf8 = ok;
  bad_utf8.text["name"] = "\xC3\x28";
  EXPECT_EQ(field_of(bad_utf8, one), "name");
  RaysetInfo long_date = ok;
  long_date.text["creation date"] = std::string(29, '1');
  EXPECT_EQ(field_of(long_date, one), "creation date");
  RaysetInfo negative = ok;
  negative.header_flux = -1;
  EXPECT_EQ(field_of(negative, one), "header flux");
  RayChunk neg = one;
  neg.flux[0] = -0.5f;
  EXPECT_EQ(field_of(ok, neg), "ray flux");
  RayChunk huge = one;
  huge.x[0] = 1e38f;  // 1e41 mm does not fit a float
  EXPECT_EQ(field_of(ok, huge), "ray position");
  fs::remove_all(d);
}

TEST(RaysetMemory, TwoMillionRaysStreamInBoundedMemory) {
  const fs::path d = scratch("tm25_memory");
  const fs::path f = d / "big.tm25ray";
  const std::uint64_t n = 2000000;
  GeneratedRays gen(n);
  RaysetInfo info = gen.info();
  info.header_flux = 0.001 * (n / 7 * 28.0);  // about the sum: 1..7 mW cycling
  const bool reset = lumx_test::reset_peak_rss();
  const long rss0 = lumx_test::proc_status_kb("VmRSS:");
  write_tm25(f.string(), info, gen);
  const long write_peak = lumx_test::proc_status_kb("VmHWM:") - rss0;
  const auto bytes = fs::file_size(f);
  EXPECT_EQ(bytes, 36288 + n * 28);

  malloc_trim(0);  // hand the writer's freed buffers back, so that reading must fault in its own pages
  lumx_test::reset_peak_rss();
  const long rss1 = lumx_test::proc_status_kb("VmRSS:");
  const auto t0 = std::chrono::steady_clock::now();
  auto src = open_rayset(f.string());
  const RaysetSummary s = summarize_rays(*src);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const long read_peak = lumx_test::proc_status_kb("VmHWM:") - rss1;
  EXPECT_EQ(s.rays, n);
  EXPECT_GT(s.flux_sum, 0);
  if (!reset) GTEST_SKIP() << "the kernel refused to reset the peak RSS; growth not measured";
  // 56 MB on disk; the window is 4 MiB and a chunk 65536 rays (1.8 MiB): far below the file.
  EXPECT_LT(write_peak * 1024.0, 16.0 * (1 << 20)) << write_peak << " kB";
  EXPECT_LT(read_peak * 1024.0, 16.0 * (1 << 20)) << read_peak << " kB";
  EXPECT_LT(read_peak * 1024.0, 0.25 * static_cast<double>(bytes));
  std::printf(
      "  2 M rays, %.1f MB: peak RSS growth writing %ld kB, reading %ld kB; summary (2 passes) %.2f s, "
      "%.0f MB/s\n",
      bytes / 1e6, write_peak, read_peak, secs, 2 * bytes / 1e6 / secs);
  fs::remove_all(d);
}

TEST(RaysetMemory, ReadSpeedOnTheLargestRealFile) {
  const auto files = real_ray_files();
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const fs::path big = *std::max_element(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return fs::file_size(a) < fs::file_size(b);
  });
  auto src = open_rayset(big.string());
  RayChunk c;
  const int passes = 10;
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t rays = 0;
  for (int i = 0; i < passes; ++i) {
    src->rewind();
    while (src->next(c, 65536)) rays += c.size();
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double mb = passes * static_cast<double>(fs::file_size(big)) / 1e6;
  EXPECT_EQ(rays, passes * src->info().ray_count);
  std::printf("  %s: %.1f MB read in %.3f s: %.0f MB/s, %.1f M rays/s\n", big.filename().string().c_str(), mb, secs,
              mb / secs, static_cast<double>(rays) / secs / 1e6);
}

TEST(RaysetMemory, SparseFileAbove4GiBUsesSixtyFourBitOffsets) {
  // 160 M rays of 28 bytes: 4.48 GB, sparse (only the header and the first rays are written).
  const fs::path d = scratch("tm25_sparse");
  const fs::path f = d / "huge.tm25ray";
  const std::uint64_t n = 160000000;
  Tm25Spec s;
  s.rows = three_rows();
  s.rays_field = n;
  write_bytes(f, build_tm25(s));
  std::error_code ec;
  fs::resize_file(f, 36288 + n * 28, ec);
  if (ec) GTEST_SKIP() << "cannot make a sparse file here: " << ec.message();
  auto src = open_rayset(f.string());
  EXPECT_EQ(src->info().ray_count, n);
  RayChunk c;
  ASSERT_TRUE(src->next(c, 3));
  EXPECT_FLOAT_EQ(c.x[0], 0.001f);
  EXPECT_EQ(c.flux[2], 1.0f);
  // One byte short: the count no longer fits, reported with the 64-bit sizes.
  fs::resize_file(f, 36288 + n * 28 - 1, ec);
  try {
    open_rayset(f.string());
    ADD_FAILURE() << "opened";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().byte_offset, 20);
    EXPECT_NE(e.diagnostic().message.find("need 4480000000 bytes"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}
