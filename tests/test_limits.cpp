// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Reader limits (docs/robustness.md §3): each one an embedder can set is named in the located error that
// exceeding it gives; JSON nested too deep is refused before parsing; and a hostile 100 MB file of each
// family (IES, TM-25, GLB, bundle manifest) is refused or read in stated time and memory bounds, measured
// in a child process so that no earlier test's peak hides the growth.
#include <lumx/bake/gltf_reader.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/gldf_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/io/tm33_io.h>

#include <gtest/gtest.h>
#include <lumx/render/image_io.h>

#include "io/bundle/exr_image.h"
#include "rayset_test_support.h"
#include "test_support.h"

#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;
using lumx_rays::Tm25Spec;

namespace {

/// The error `read` throws; a failure if it throws none.
Diagnostic error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const Error& e) {
    return e.diagnostic();
  }
  ADD_FAILURE() << "no error";
  return {};
}

/// `read` fails with an error located somewhere (line, byte offset or JSON pointer) that names `limit`.
void expect_named(const std::function<void()>& read, const std::string& limit) {
  const Diagnostic d = error_of(read);
  EXPECT_NE(d.message.find(limit), std::string::npos) << d.str();
  EXPECT_TRUE(d.line > 0 || d.byte_offset >= 0 || (!d.field.empty() && d.field.front() == '/') || d.field == "file" ||
              d.file.find("!/") != std::string::npos ||
              d.field == "file size" || d.field == "manifest" || d.field == "ZIP" || d.field == "levels")
      << d.str();
  EXPECT_FALSE(d.file.empty()) << d.str();
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("lumx_limits_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_file(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

/// Writes `head` and extends the file to `size` bytes with a hole (zeros, no disk blocks).
void write_sparse(const fs::path& p, const std::string& head, std::uint64_t size) {
  write_file(p, head);
  ASSERT_EQ(::truncate(p.c_str(), static_cast<off_t>(size)), 0);
}

/// A bundle folder made of the fuzz seed (one level, one 8 x 8 map).
fs::path seed_bundle(const fs::path& dir) {
  const fs::path b = dir / "seed.lumx";
  fs::create_directories(b / "levels");
  const fs::path seed = lumx_test::data_dir() / "fuzz" / "bundle";
  fs::copy_file(seed / "manifest.json", b / "manifest.json");
  fs::copy_file(seed / "level00_n00001_r0008.exr", b / "levels" / "level00_n00001_r0008.exr");
  return b;
}

/// What a read did in a child process: its error (if any), its wall time and how much its peak RSS grew.
struct Bounded {
  bool threw = false;
  std::string field, message;
  int line = 0;
  long long byte_offset = -1;
  double seconds = 0;
  long grown_kb = 0;
};

/// `address_space_mb` > 0: the child may map at most that much more address space (RLIMIT_AS above its
/// own size), so an allocation it does not touch — invisible to the RSS — fails; ignored under ASan, whose
/// shadow memory needs terabytes of address space.
Bounded run_bounded(const std::function<void()>& read, long address_space_mb = 0) {
  int fds[2];
  if (::pipe(fds) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
#if !defined(__SANITIZE_ADDRESS__)
    if (address_space_mb > 0) {
      long pages = 0;
      std::ifstream("/proc/self/statm") >> pages;  // total program size, in pages
      const rlim_t limit = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + rlim_t(address_space_mb) * (1u << 20);
      const struct rlimit rl {limit, limit};
      ::setrlimit(RLIMIT_AS, &rl);
    }
#else
    (void)address_space_mb;
#endif
    struct rusage ru {};
    ::getrusage(RUSAGE_SELF, &ru);
    const long before = ru.ru_maxrss;
    std::string out;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      read();
      out = "0\n0\n-1\n\n\n";
    } catch (const Error& e) {
      const Diagnostic& d = e.diagnostic();
      out = "1\n" + std::to_string(d.line) + "\n" + std::to_string(d.byte_offset) + "\n" + d.field + "\n" +
            d.message.substr(0, d.message.find('\n')) + "\n";
    } catch (const std::exception& e) {
      out = "2\n0\n-1\n\n" + std::string(e.what()) + "\n";
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ::getrusage(RUSAGE_SELF, &ru);
    out += std::to_string(s) + "\n" + std::to_string(ru.ru_maxrss - before) + "\n";
    if (::write(fds[1], out.data(), out.size()) != static_cast<ssize_t>(out.size())) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  Bounded r;
  std::istringstream in(text);
  std::string kind, line, offset, seconds, grown;
  std::getline(in, kind), std::getline(in, line), std::getline(in, offset), std::getline(in, r.field);
  std::getline(in, r.message), std::getline(in, seconds), std::getline(in, grown);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the child died: " << text;
  EXPECT_NE(kind, "2") << "not a lumx::Error: " << r.message;
  r.threw = kind == "1";
  r.line = line.empty() ? 0 : std::stoi(line);
  r.byte_offset = offset.empty() ? -1 : std::stoll(offset);
  r.seconds = seconds.empty() ? 1e9 : std::stod(seconds);
  r.grown_kb = grown.empty() ? 1L << 40 : std::stol(grown);
  return r;
}

constexpr std::uint64_t kHostileBytes = 100'000'000;

// The time bounds are for an optimised build; the sanitizer build (Debug, ASan + UBSan) gets ten times as long.
#if defined(__SANITIZE_ADDRESS__) || !defined(NDEBUG)
constexpr double kSlow = 10;
#else
constexpr double kSlow = 1;
#endif
constexpr long kFileKb = static_cast<long>(kHostileBytes / 1024);
// AddressSanitizer keeps one shadow byte per 8 bytes of application memory touched, plus redzones and a
// quarantine of freed blocks: in that build its resident size may grow by about an eighth of the file plus
// allocator slack on top of the bounds below, which hold for the library itself.
#if defined(__SANITIZE_ADDRESS__)
constexpr long kSanitizerKb = kFileKb / 8 + 16 * 1024;
#else
constexpr long kSanitizerKb = 0;
#endif

const char* kIes =
    "IESNA:LM-63-2002\n[TEST] T\nTILT=NONE\n1 -1 1 3 5 1 2 0 0 0\n1 1 10\n0 45 90\n0 90 180 270 360\n"
    "100 80 10\n100 60 10\n100 50 10\n100 60 10\n100 80 10\n";

}  // namespace

TEST(Robustness, PhotometryLimitsAreNamedInLocatedErrors) {
  const fs::path d = fresh_dir("photometry");
  auto with = [](const std::function<void(ReadLimits&)>& set) {
    ReadOptions o;
    o.warnings = [](const Diagnostic&) {};
    set(o.limits);
    return o;
  };
  const ReadOptions two_angles = with([](ReadLimits& l) { l.max_angles = 2; });
  const ReadOptions small_file = with([](ReadLimits& l) { l.max_file_bytes = 100; });
  const ReadOptions no_lamps = with([](ReadLimits& l) { l.max_lamp_sets = 0; });
  write_file(d / "t.ies", kIes);
  expect_named([&] { read_photometry((d / "t.ies").string(), small_file); }, "ReadLimits::max_file_bytes (100)");
  expect_named([&] { read_ies(kIes, "t.ies", small_file); }, "ReadLimits::max_file_bytes (100)");
  expect_named([&] { read_ies(kIes, "t.ies", two_angles); }, "ReadLimits::max_angles (2)");
  const std::string tilt = "IESNA:LM-63-2002\n[TEST] T\nTILT=INCLUDE\n1\n3\n0 45 90\n1 1 1\n";
  expect_named([&] { read_ies(tilt, "t.ies", two_angles); }, "ReadLimits::max_angles (2)");

  const std::string ldt = lumx_test::read_text(lumx_test::data_dir() / "ldt" / "isym2_point.ldt");
  expect_named([&] { read_ldt(ldt, "t.ldt", small_file); }, "ReadLimits::max_file_bytes (100)");
  expect_named([&] { read_ldt(ldt, "t.ldt", two_angles); }, "ReadLimits::max_angles is 2");
  expect_named([&] { read_ldt(ldt, "t.ldt", no_lamps); }, "ReadLimits::max_lamp_sets is 0");

  const std::string xml = lumx_test::read_text(lumx_test::data_dir() / "tm33" / "downlight_tm33_23.xml");
  const std::string json = lumx_test::read_text(lumx_test::data_dir() / "tm33" / "downlight_tm33_23.json");
  expect_named([&] { read_tm33_xml(xml, "t.xml", small_file); }, "ReadLimits::max_file_bytes (100)");
  expect_named([&] { read_tm33_json(json, "t.json", small_file); }, "ReadLimits::max_file_bytes (100)");
  expect_named([&] { read_tm33_xml(xml, "t.xml", two_angles); }, "ReadLimits::max_angles");
  expect_named([&] { read_tm33_json(json, "t.json", two_angles); }, "ReadLimits::max_angles");
  expect_named([&] { read_tm33_xml(xml, "t.xml", no_lamps); }, "ReadLimits::max_lamp_sets (0)");
  fs::remove_all(d);
}

TEST(Robustness, RaysetLimitsAreNamedInLocatedErrors) {
  const fs::path d = fresh_dir("rays");
  auto open_with = [](const fs::path& p, const std::function<void(RaysetLimits&)>& set) {
    RaysetReadOptions o;
    o.warnings = [](const Diagnostic&) {};
    set(o.limits);
    auto rays = open_rayset(p.string(), o);
    (void)summarize_rays(*rays);
  };
  Tm25Spec s;
  s.spectral = 3;
  s.lambda_min = 400, s.lambda_max = 700;
  s.tables = {{{400, 0.5f}, {500, 1}, {550, 0.9f}, {600, 0.4f}, {700, 0.1f}}};
  s.column_names = {"temperature", "id"};
  s.additional_text = "measured 2016";
  for (int i = 0; i < 4; ++i) s.rows.push_back({float(i), 1, 2, 0, 0, 1, 0.25f, 300.0f + i, float(i)});
  const fs::path tm25 = d / "full.tm25ray";
  write_file(tm25, lumx_rays::build_tm25(s));
  ASSERT_NO_THROW(open_with(tm25, [](RaysetLimits&) {}));
  expect_named([&] { open_with(tm25, [](RaysetLimits& l) { l.max_rays = 3; }); }, "RaysetLimits::max_rays (3)");
  expect_named([&] { open_with(tm25, [](RaysetLimits& l) { l.max_spectral_tables = 0; }); },
               "RaysetLimits::max_spectral_tables (0)");
  expect_named([&] { open_with(tm25, [](RaysetLimits& l) { l.max_spectral_points = 4; }); },
               "RaysetLimits::max_spectral_points (4)");
  expect_named([&] { open_with(tm25, [](RaysetLimits& l) { l.max_additional_items = 1; }); },
               "RaysetLimits::max_additional_items (1)");
  expect_named([&] { open_with(tm25, [](RaysetLimits& l) { l.max_text_bytes = 32; }); },
               "RaysetLimits::max_text_bytes (32)");

  const fs::path plain = lumx_test::data_dir() / "fuzz" / "rayset" / "plain.txt";
  expect_named([&] { open_with(plain, [](RaysetLimits& l) { l.max_rays = 1; }); }, "RaysetLimits::max_rays (1)");
  expect_named([&] { open_with(plain, [](RaysetLimits& l) { l.max_line_bytes = 20; }); },
               "RaysetLimits::max_line_bytes (20)");
  const fs::path lt = d / "header.txt";
  write_file(lt, "lt_rdf_version: 1.0\nlt_length_units: mm\nlt_color_info: none\n");
  auto lighttools = [&](std::size_t lines) {
    RaysetReadOptions o;
    o.format = RaysetFormat::lighttools_text;
    o.limits.max_header_lines = lines;
    (void)open_rayset(lt.string(), o);
  };
  expect_named([&] { lighttools(2); }, "RaysetLimits::max_header_lines (2)");
  fs::remove_all(d);
}

TEST(Robustness, BundleAndGldfLimitsAreNamedInLocatedErrors) {
  const fs::path d = fresh_dir("bundle");
  const fs::path b = seed_bundle(d);
  auto open_with = [&](const std::function<void(BundleLimits&)>& set) {
    BundleLimits l;
    set(l);
    const BundleReader r(b.string(), l);
    (void)r.load();
  };
  ASSERT_NO_THROW(open_with([](BundleLimits&) {}));
  expect_named([&] { open_with([](BundleLimits& l) { l.max_manifest_bytes = 100; }); },
               "BundleLimits::max_manifest_bytes (100)");
  expect_named([&] { open_with([](BundleLimits& l) { l.max_levels = 0; }); }, "BundleLimits::max_levels (0)");
  expect_named([&] { open_with([](BundleLimits& l) { l.max_apls_per_level = 0; }); },
               "BundleLimits::max_apls_per_level (0)");
  expect_named([&] { open_with([](BundleLimits& l) { l.max_payload_bytes = 100; }); },
               "BundleLimits::max_payload_bytes (100)");
  expect_named([&] { open_with([](BundleLimits& l) { l.max_decoded_bytes = 100; }); },
               "BundleLimits::max_decoded_bytes (100)");
  expect_named([&] { open_with([](BundleLimits& l) { l.max_loaded_bytes = 100; }); },
               "BundleLimits::max_loaded_bytes (100)");

  const fs::path gldf = lumx_test::data_dir() / "fuzz" / "gldf" / "eulumdat_deflated.gldf";
  auto gldf_with = [&](const std::function<void(GldfLimits&)>& set) {
    GldfReadOptions o;
    set(o.limits);
    const GldfContainer c = read_gldf(gldf.string(), o);
    (void)read_gldf_photometry(c, c.files.at(0), o);
  };
  ASSERT_NO_THROW(gldf_with([](GldfLimits&) {}));
  expect_named([&] { gldf_with([](GldfLimits& l) { l.max_archive_bytes = 100; }); },
               "GldfLimits::max_archive_bytes (100)");
  expect_named([&] { gldf_with([](GldfLimits& l) { l.max_entries = 1; }); }, "GldfLimits::max_entries (1)");
  expect_named([&] { gldf_with([](GldfLimits& l) { l.max_entry_bytes = 100; }); },
               "GldfLimits::max_entry_bytes (100)");
  expect_named([&] { gldf_with([](GldfLimits& l) { l.max_total_bytes = 1000; }); },
               "GldfLimits::max_total_bytes (1000)");
  fs::remove_all(d);
}

TEST(Robustness, JsonNestedDeeperThan256LevelsIsRefusedBeforeParsing) {
  // Each bracket would become a value of its own (~80 bytes of heap): 1 MiB of them, ~80 MiB.
  const std::string deep = std::string(1u << 20, '[') + std::string(1u << 20, ']');
  const std::string fine = std::string(256, '[') + std::string(256, ']');
  Diagnostic d = error_of([&] { read_tm33_json(deep, "deep.json"); });
  EXPECT_EQ(d.field, "JSON");
  EXPECT_EQ(d.line, 1);
  EXPECT_NE(d.message.find("256 levels"), std::string::npos) << d.str();
  d = error_of([&] { read_tm33_json(fine, "fine.json"); });  // parsed, then refused as no TM-33 document
  EXPECT_EQ(d.message.find("256 levels"), std::string::npos) << d.str();

  const fs::path dir = fresh_dir("deep");
  const fs::path b = seed_bundle(dir);
  write_file(b / "manifest.json", "{\"levels\": " + deep + "}");
  d = error_of([&] { BundleReader r(b.string()); });
  EXPECT_EQ(d.field, "JSON");
  EXPECT_EQ(d.byte_offset, 11 + 255);  // the bracket that opens level 257
  fs::remove_all(dir);
}

TEST(Robustness, ExrAttributeLargerThanThePayloadIsRefusedBeforeOpenExrAllocates) {
  // Found by fuzz_bundle (tests/data/fuzz/bundle/exr_attribute_2gib.exr): OpenEXR allocates and clears an
  // attribute's declared size before reading it, 2 GiB here for a 29-byte payload.
  const std::string exr = lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "exr_attribute_2gib.exr");
  ASSERT_EQ(exr.size(), 29u);
  const Bounded r = run_bounded([&] { (void)detail::decode_exr(exr, "a.exr", 16, 8, {"Y"}); });
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.byte_offset, 24) << r.message;  // the attribute's size field
  EXPECT_NE(r.message.find("2147483647"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  // A payload lumx wrote still decodes.
  const std::string good =
      lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "level00_n00001_r0008.exr");
  EXPECT_EQ(detail::decode_exr(good, "good.exr", 16, 8, {"Y"}).pixels.size(), 128u);
}

TEST(Robustness, ExrDataWindowIsCheckedBeforeOpenExrSizesItsLineBuffers) {
  // Found by fuzz_bundle (exr_zip_line_buffer_1gib.exr, 223 bytes): a ZIP-compressed header declaring
  // 33 554 448 × 8 half pixels. Opening it, OpenEXR allocates its line buffers (1 GiB for the ZIP
  // compressor's 16 lines) before lumx could compare the window with the manifest's shape: never touched in a release
  // build (0.09 s), 4 s and 172 MB under ASan. The window is now read by the header walk and checked first.
  // With 256 MiB of address space to spare, the old order failed in OpenEXR (std::bad_alloc).
  const std::string exr =
      lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "exr_zip_line_buffer_1gib.exr");
  ASSERT_EQ(exr.size(), 223u);
  Bounded r = run_bounded([&] { (void)detail::decode_exr(exr, "z.exr", 16, 8, {"Y"}); }, 256);
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.field, "dataWindow") << r.message;
  EXPECT_NE(r.message.find("33554448 × 8"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  // read_exr_image has no expected shape: the window is refused by ImageReadLimits::max_values, first.
  const fs::path d = fresh_dir("exr_zip");
  std::ofstream(d / "z.exr", std::ios::binary) << exr;
  r = run_bounded([&] { (void)read_exr_image((d / "z.exr").string()); }, 256);
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.field, "dataWindow") << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  fs::remove_all(d);
}

TEST(Robustness, ExrHeadersOpenExrWouldReadElsewhereAreRefused) {
  // Found by fuzz_bundle (exr_chlist_desync.exr, 465 bytes): a channel list that does not end where its
  // size says made OpenEXR read the next attribute at another offset, whose bytes became a 1.9 GB size.
  const std::string exr = lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "exr_chlist_desync.exr");
  Bounded r = run_bounded([&] { (void)detail::decode_exr(exr, "a.exr", 16, 8, {"Y"}); });
  EXPECT_TRUE(r.threw);
  // Its second channel's name starts at byte 46 and runs past the list's declared 19 bytes.
  EXPECT_EQ(r.byte_offset, 46) << r.message;
  EXPECT_NE(r.message.find("channel name is not terminated"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  // A payload lumx wrote, with the data window's size field (box2i: 16 bytes) changed to 4 and to 20.
  const std::string good =
      lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "level00_n00001_r0008.exr");
  const std::size_t type = good.find(std::string("dataWindow\0box2i\0", 17));
  ASSERT_NE(type, std::string::npos);
  for (const char size : {char(4), char(20)}) {
    std::string bad = good;
    bad[type + 17] = size;
    try {
      (void)detail::decode_exr(bad, "b.exr", 16, 8, {"Y"});
      ADD_FAILURE() << "a box2i of " << int(size) << " bytes was read";
    } catch (const Error& e) {
      EXPECT_EQ(e.diagnostic().byte_offset, std::int64_t(type + 17)) << e.what();
      EXPECT_NE(std::string(e.what()).find("its type has 16"), std::string::npos) << e.what();
    }
  }
  // A float vector whose size is not a multiple of 4 (OpenEXR would read 4 of 5 bytes and go on one byte
  // early): an attribute inserted before the end of a lumx payload's header.
  {
    const std::size_t header_end = good.find(std::string("screenWindowWidth\0float\0\4\0\0\0", 28)) + 28 + 4;
    ASSERT_GT(header_end, 32u);
    std::string bad = good.substr(0, header_end) + std::string("extra\0floatvector\0\5\0\0\0", 22) +
                      std::string(5, '\0') + good.substr(header_end);
    try {
      (void)detail::decode_exr(bad, "v.exr", 16, 8, {"Y"});
      ADD_FAILURE() << "a float vector of 5 bytes was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("floatvector"), std::string::npos) << e.what();
      EXPECT_EQ(e.diagnostic().byte_offset, std::int64_t(header_end + 18)) << e.what();  // its size field
    }
  }
  // A data window of 16 × 2²⁴, 2²⁰ × 2²⁰ or 2³¹ × 2³¹ pixels in a 400-byte payload (hard-cases.md §6 item
  // 27): refused, by the bundle's expected shape or by OpenEXR's own checks of the line offsets against the
  // file, in under a second and 64 MiB, by decode_exr and by read_exr_image.
  const std::size_t window = good.find(std::string("dataWindow\0box2i\0", 17)) + 17 + 4;
  const fs::path dw = fresh_dir("exr_window");
  for (const auto& [x_max, y_max] : {std::pair<std::int32_t, std::int32_t>{15, (1 << 24) - 1},
                                     {(1 << 20) - 1, (1 << 20) - 1}, {0x7fffffff, 0x7fffffff}}) {
    std::string bad = good;
    for (int k = 0; k < 4; ++k) {
      bad[window + 8 + k] = char(std::uint32_t(x_max) >> (8 * k));
      bad[window + 12 + k] = char(std::uint32_t(y_max) >> (8 * k));
    }
    r = run_bounded([&] { (void)detail::decode_exr(bad, "w.exr", 16, 8, {"Y"}); });
    EXPECT_TRUE(r.threw) << x_max << " " << y_max;
    EXPECT_LT(r.seconds, 1.0 * kSlow);
    EXPECT_LT(r.grown_kb, 64 * 1024 + kSanitizerKb) << x_max << " " << y_max;
    std::ofstream(dw / "w.exr", std::ios::binary | std::ios::trunc) << bad;
    r = run_bounded([&] { (void)read_exr_image((dw / "w.exr").string()); });
    EXPECT_TRUE(r.threw) << x_max << " " << y_max;
    EXPECT_LT(r.seconds, 1.0 * kSlow);
    EXPECT_LT(r.grown_kb, 64 * 1024 + kSanitizerKb) << x_max << " " << y_max;
  }
  fs::remove_all(dw);
  // The same checks guard read_exr_image (any EXR, not only a bundle's): the 2 GiB attribute is refused.
  const fs::path d = fresh_dir("exr_image");
  const fs::path huge = d / "huge_attribute.exr";
  std::ofstream(huge, std::ios::binary) << lumx_test::read_text(lumx_test::data_dir() / "fuzz" / "bundle" / "exr_attribute_2gib.exr");
  r = run_bounded([&] { (void)read_exr_image(huge.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  fs::remove_all(d);
}

TEST(Robustness, RefusedBundlesLeaveNoFileDescriptorOpen) {
  // Found by fuzz_bundle: every refused manifest left the bundle's folder open, until fopen failed.
  const fs::path d = fresh_dir("fds");
  const fs::path b = seed_bundle(d);
  write_file(b / "manifest.json", "{\"format\": 1}");
  auto open_fds = [] {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator("/proc/self/fd")) n += e.exists() ? 1 : 0;
    return n;
  };
  const std::size_t before = open_fds();
  for (int i = 0; i < 100; ++i) EXPECT_THROW(BundleReader r(b.string()), Error);
  EXPECT_EQ(open_fds(), before);
  fs::remove_all(d);
}

// ---- hostile 100 MB files: refused, or read in bounded time and memory -----------------------------------

TEST(Robustness, Hostile100MBIesFileIsRefusedOrReadInBoundedTimeAndMemory) {
  const fs::path d = fresh_dir("ies100");
  const fs::path p = d / "huge.ies";
  // A header announcing 3601 x 3601 values, then 100 MB of NUL bytes (a hole: no disk blocks).
  write_sparse(p, "IESNA:LM-63-2002\n[TEST] T\nTILT=NONE\n1 -1 1 3601 3601 1 2 0 0 0\n1 1 10\n", kHostileBytes);
  // Default limits: refused from its size alone, nothing read (< 1 s, < 8 MiB).
  Bounded r = run_bounded([&] { read_photometry(p.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_NE(r.message.find("ReadLimits::max_file_bytes"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  // Limit raised to 128 MiB: read once into memory and refused at the line where the values stop
  // (< 5 s; memory: the text itself plus < 16 MiB, never the 3601 x 3601 table).
  ReadOptions raised;
  raised.limits.max_file_bytes = 128u << 20;
  r = run_bounded([&] { read_photometry(p.string(), raised); });
  EXPECT_TRUE(r.threw);
  EXPECT_TRUE(r.line == 5 || r.line == 6) << r.line << ": " << r.message;  // where the values stop
  EXPECT_LT(r.seconds, 5.0 * kSlow);
  EXPECT_LT(r.grown_kb, kFileKb + 16 * 1024 + kSanitizerKb);
  fs::remove_all(d);
}

TEST(Robustness, Hostile100MBTm25FileIsReadInBoundedTimeAndMemory) {
  const fs::path d = fresh_dir("tm25_100");
  const fs::path p = d / "huge.tm25ray";
  // A valid header and first ray, announcing as many 28-byte rays as fill 100 MB; the rest is a hole of
  // zeros, so ray 2 has a zero direction.
  Tm25Spec s;
  s.rows = {{0, 0, 0, 0, 0, 1, 1}};
  const std::string one = lumx_rays::build_tm25(s);
  const std::uint64_t header = one.size() - 28;
  s.rays_field = (kHostileBytes - header) / 28;
  write_sparse(p, lumx_rays::build_tm25(s), header + *s.rays_field * 28);
  Bounded r = run_bounded([&] {
    RaysetReadOptions o;
    o.warnings = [](const Diagnostic&) {};
    auto rays = open_rayset(p.string(), o);
    (void)summarize_rays(*rays);
  });
  // Streamed in chunks: an error at ray 2's bytes, < 1 s, < 16 MiB whatever the file's size.
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.byte_offset, static_cast<long long>(header + 28 + 12)) << r.message;  // its direction
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 16 * 1024 + kSanitizerKb);
  // Announcing one ray more than the file holds: refused from the header alone.
  s.rays_field = *s.rays_field + 1;
  write_file(p, lumx_rays::build_tm25(s));
  ASSERT_EQ(::truncate(p.c_str(), static_cast<off_t>(header + (*s.rays_field - 1) * 28)), 0);
  r = run_bounded([&] { (void)open_rayset(p.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.byte_offset, 20) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  fs::remove_all(d);
}

TEST(Robustness, Hostile100MBGlbIsRefusedInBoundedTimeAndMemory) {
  const fs::path d = fresh_dir("glb100");
  const fs::path p = d / "huge.glb";
  // A GLB whose BIN chunk fills 100 MB (a hole of zeros) and whose accessor announces 2^31 vertices.
  const std::uint64_t bin = kHostileBytes - 4096;
  std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
                     R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],)"
                     R"("materials":[{"emissiveFactor":[1,1,1]}],)"
                     R"("accessors":[{"bufferView":0,"componentType":5126,"count":2147483648,"type":"VEC3"}],)"
                     R"("bufferViews":[{"buffer":0,"byteLength":)" +
                     std::to_string(bin) + R"(}],"buffers":[{"byteLength":)" + std::to_string(bin) + "}]}";
  json.resize(4096 - 28, ' ');
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string head = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(kHostileBytes)) +
                           u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json +
                           u32(static_cast<std::uint32_t>(bin)) + std::string("BIN\0", 4);
  ASSERT_EQ(head.size(), 4096u);
  write_sparse(p, head, kHostileBytes);
  // Default limits: the file is read once (it is below GltfReadOptions::max_file_bytes), then the accessor
  // is refused before anything is sized from its count (< 5 s; memory: the file plus < 16 MiB).
  Bounded r = run_bounded([&] { (void)bake::read_gltf_luminaire(p.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.field, "/accessors/0/count") << r.message;
  EXPECT_NE(r.message.find("GltfReadOptions::max_vertices"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 5.0 * kSlow);
  EXPECT_LT(r.grown_kb, kFileKb + 16 * 1024 + kSanitizerKb);
  // A 64 MiB file limit: refused from the size alone (< 1 s, < 8 MiB).
  bake::GltfReadOptions small;
  small.max_file_bytes = 64u << 20;
  r = run_bounded([&] { (void)bake::read_gltf_luminaire(p.string(), small); });
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.byte_offset, 0) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  fs::remove_all(d);
}

TEST(Robustness, Hostile100MBManifestIsRefusedInBoundedTimeAndMemory) {
  const fs::path d = fresh_dir("manifest100");
  const fs::path b = seed_bundle(d);
  // 100 MB of nested arrays: ~8 GB of JSON values if it were parsed.
  {
    std::ofstream f(b / "manifest.json", std::ios::binary);
    const std::string block(1u << 20, '[');
    for (std::uint64_t n = 0; n < kHostileBytes; n += block.size()) f << block;
  }
  // Default limits: refused from its size (BundleLimits::max_manifest_bytes, 64 MiB), nothing read.
  Bounded r = run_bounded([&] { BundleReader reader(b.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_NE(r.message.find("BundleLimits::max_manifest_bytes"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  // Limit raised to 128 MiB: read once, refused at the bracket that opens level 257 before parsing
  // (< 5 s; memory: the text plus < 16 MiB).
  BundleLimits raised;
  raised.max_manifest_bytes = 128u << 20;
  r = run_bounded([&] { BundleReader reader(b.string(), raised); });
  EXPECT_TRUE(r.threw);
  EXPECT_EQ(r.byte_offset, 256) << r.message;
  EXPECT_LT(r.seconds, 5.0 * kSlow);
  EXPECT_LT(r.grown_kb, kFileKb + 16 * 1024 + kSanitizerKb);
  // A manifest that is one 2 GiB string (hard-cases.md §6 item 30; a sparse file, so the test writes 12
  // bytes): refused from its size, nothing read, whatever the string holds.
  {
    std::ofstream f(b / "manifest.json", std::ios::binary | std::ios::trunc);
    f << "{\"format\": \"";
  }
  fs::resize_file(b / "manifest.json", (std::uint64_t(2) << 30) + 2);
  r = run_bounded([&] { BundleReader reader(b.string()); });
  EXPECT_TRUE(r.threw);
  EXPECT_NE(r.message.find("BundleLimits::max_manifest_bytes"), std::string::npos) << r.message;
  EXPECT_LT(r.seconds, 1.0 * kSlow);
  EXPECT_LT(r.grown_kb, 8 * 1024 + kSanitizerKb);
  fs::remove_all(d);
}
