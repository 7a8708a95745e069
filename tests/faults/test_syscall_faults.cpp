// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Writes that fail at the system-call level (hard-cases.md §6 items 36–37; docs/robustness.md §4): write
// or pwrite reporting ENOSPC or EIO once k bytes went out, for every k of a small file; short writes; fsync
// and close reporting EIO. Each failure must be a lumx::Error naming the file and the failed step, leave
// the previous file (or bundle) byte for byte, and leave no temporary behind. A crash at that moment would
// leave the same state, with at most a temporary that the next write removes (tests/test_killed_writes.cpp).
#include <lumx/apl/apl_set.h>
#include <lumx/io/bundle_io.h>
#include <lumx/render/image_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/render/image.h>

#include <gtest/gtest.h>

#include "syscall_faults.h"
#include "luminaire_test_scenes.h"
#include "test_support.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;
using lumx_faults::Armed;
using lumx_faults::Call;
using lumx_faults::Fault;

namespace {

fs::path fresh_dir(const std::string& name) { return lumx_test::fresh_temp_dir("lumx_faults_" + name); }

std::string slurp(const fs::path& p) { return lumx_test::read_text(p); }

/// Everything in `folder` except `keep`: temporaries (".NAME.tmp-PID-N") and scratch bundles.
std::vector<std::string> leftovers(const fs::path& folder, const fs::path& keep) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.path() != keep) out.push_back(e.path().filename().string());
  return out;
}

/// The error `write` throws while `fault` is armed ("" when it throws none), and how many calls failed.
std::string failure_of(const Fault& fault, const std::function<void()>& write, int* failures = nullptr) {
  std::string what;
  {
    Armed armed(fault);
    try {
      write();
    } catch (const Error& e) {
      what = e.what();
    }
    if (failures) *failures = lumx_faults::failures_injected();
  }
  return what;
}

/// Bytes the armed writer sends to regular files when nothing fails.
std::uint64_t bytes_of(const std::function<void()>& write) {
  Armed armed(Fault{});
  write();
  return lumx_faults::bytes_written();
}

/// The contract for one writer of one file: `old_version` is on disk; `write_new` must, for ENOSPC at every
/// k-th byte in `stride` steps (and EIO at a few), for a failing fsync and a failing close, throw an error
/// naming `target` and the step, and leave `target` as it was and nothing else in its folder. Short writes
/// must produce the same bytes as an unhindered write.
void expect_failed_writes_keep_the_old_file(const fs::path& target, const std::function<void()>& write_old,
                                            const std::function<void()>& write_new, std::uint64_t stride) {
  write_new();
  const std::string fresh = slurp(target);
  write_old();
  const std::string old = slurp(target);
  ASSERT_NE(old, fresh);
  const std::uint64_t total = bytes_of(write_new);
  ASSERT_GE(total, fresh.size());
  write_old();  // bytes_of replaced it

  auto expect_intact = [&](const std::string& what, const std::string& step, const std::string& why) {
    EXPECT_NE(what.find(target.string()), std::string::npos) << why << ": " << what;
    EXPECT_NE(what.find(step), std::string::npos) << why << ": " << what;
    EXPECT_EQ(slurp(target), old) << why;
    EXPECT_TRUE(leftovers(target.parent_path(), target).empty()) << why;
  };
  int checked = 0;
  for (std::uint64_t k = 0; k < total; k += stride, ++checked) {
    int failures = 0;
    const std::string what = failure_of({Call::write, ENOSPC, k}, write_new, &failures);
    ASSERT_EQ(failures, 1) << "byte " << k;
    expect_intact(what, std::strerror(ENOSPC), "ENOSPC at byte " + std::to_string(k));
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(checked, 10);
  for (const std::uint64_t k : {std::uint64_t(0), total / 2, total - 1}) {
    const std::string what = failure_of({Call::write, EIO, k}, write_new);
    expect_intact(what, std::strerror(EIO), "EIO at byte " + std::to_string(k));
  }
  expect_intact(failure_of({Call::fsync_file, EIO}, write_new), "fsync", "fsync of the file");
  expect_intact(failure_of({Call::close_file, EIO}, write_new), "close", "close of the file");

  // Short writes are continued, not mistaken for the end: 7 bytes at a time gives the same file.
  Fault short_writes;
  short_writes.max_chunk = 7;
  EXPECT_EQ(failure_of(short_writes, write_new), "");
  EXPECT_EQ(slurp(target), fresh);
  EXPECT_TRUE(leftovers(target.parent_path(), target).empty());
}

Photometry table(double scale) {
  std::ostringstream s;
  s << "IESNA:LM-63-2002\n[TEST] faults\nTILT=NONE\n1 -1 1 19 5 1 2 0 0 0\n1 1 10\n";
  for (int i = 0; i < 19; ++i) s << 10 * i << ' ';
  s << "\n0 90 180 270 360\n";
  for (int h = 0; h < 5; ++h) {
    for (int v = 0; v < 19; ++v) s << scale * (100 + 10 * (h % 4) + 50 * std::cos(v * M_PI / 18)) << ' ';
    s << '\n';
  }
  return read_ies(s.str(), "faults.ies");
}

}  // namespace

TEST(SyscallFaults, InjectionReachesTheLibrary) {
  // The test can fail: without the interposed calls no fault would be seen.
  const fs::path d = fresh_dir("reach");
  const std::string what = failure_of({Call::write, ENOSPC, 0}, [&] { write_photometry(table(1), (d / "a.ies").string()); });
  EXPECT_NE(what.find("write"), std::string::npos) << what;
  EXPECT_FALSE(fs::exists(d / "a.ies"));
  EXPECT_TRUE(fs::is_empty(d));
  fs::remove_all(d);
}

// Every byte k of a 1.5–6 kB file, for each photometry format (write_file_atomically); every 7th byte in
// the sanitizer build, where each attempt costs ten times as much.
TEST(SyscallFaults, PhotometryWritesFailingAtEveryByteKeepTheOldFile) {
#if defined(__SANITIZE_ADDRESS__)
  const std::uint64_t stride = 7;
#else
  const std::uint64_t stride = 1;
#endif
  const Photometry a = table(1), b = table(2);
  for (const std::string name : {"l.ies", "l.ldt", "l.xml", "l.json"}) {
    SCOPED_TRACE(name);
    const fs::path d = fresh_dir("photometry");
    const fs::path target = d / name;
    expect_failed_writes_keep_the_old_file(
        target, [&] { write_photometry(a, target.string()); }, [&] { write_photometry(b, target.string()); }, stride);
    fs::remove_all(d);
  }
}

// The streamed TM-25 writer (AtomicStreamFile: buffered writes, a pwrite of the header, fsync, close).
TEST(SyscallFaults, Tm25WritesFailingAnywhereKeepTheOldFile) {
  const fs::path d = fresh_dir("tm25");
  const fs::path target = d / "rays.tm25ray";
  auto write_rays = [&](float flux) {
    RayChunk rays;
    for (int i = 0; i < 300; ++i) {
      const float t = 0.01f * float(i);
      rays.push_back({std::cos(t) * 0.01f, std::sin(t) * 0.01f, 0}, {0, 0, -1}, flux);
    }
    RaysetInfo info;
    info.format = "TM-25";
    MemoryRaySource source(std::move(rays), info);
    write_tm25(target.string(), info, source);
  };
  {  // the header is completed with pwrite: the interposition must see it, or part of the writer is untested
    Armed watch(Fault{});
    write_rays(3e-3f);
    EXPECT_GT(lumx_faults::bytes_pwritten(), 0u);
  }
  expect_failed_writes_keep_the_old_file(target, [&] { write_rays(1e-3f); }, [&] { write_rays(2e-3f); }, 37);
  fs::remove_all(d);
}

TEST(SyscallFaults, ExrImageWritesFailingAnywhereKeepTheOldFile) {
  const fs::path d = fresh_dir("exr");
  const fs::path target = d / "image.exr";
  auto write_image = [&](float v) {
    render::Image image(16, 8, {"Y"});
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) image.at(x, y, 0) = v * float(x + y);
    write_exr_image(target.string(), image);
  };
  expect_failed_writes_keep_the_old_file(target, [&] { write_image(1); }, [&] { write_image(2); }, 11);
  fs::remove_all(d);
}

// A glTF luminaire (.glb, and .gltf with its buffer as a data URI): one write through write_file_atomically.
TEST(SyscallFaults, GltfLuminaireWritesFailingAnywhereKeepTheOldFile) {
  for (const bool binary : {true, false}) {
    const fs::path d = fresh_dir(binary ? "glb" : "gltf");
    const fs::path target = d / (binary ? "luminaire.glb" : "luminaire.gltf");
    auto write_luminaire = [&](double albedo) { lumx_test::write_white_sphere_luminaire(target, 4, 6, albedo, binary); };
    expect_failed_writes_keep_the_old_file(target, [&] { write_luminaire(0.8); }, [&] { write_luminaire(0.5); }, 97);
    fs::remove_all(d);
  }
}

namespace {

/// A two-level set of small maps whose values scale with `scale`.
AplSet small_set(float scale) {
  AplSet set;
  set.provenance["test"] = "syscall faults";
  const int R = 8;
  AplLevel coarse, fine;
  coarse.map_resolution = fine.map_resolution = R;
  Apl root;
  root.map = SphereMap(R, 1);
  for (int i = 0; i < 4; ++i) {
    Apl a;
    a.position = {0.05f * float(i), 0.0f, 0.0f};
    a.parent = 0;
    a.map = SphereMap(R, 1);
    for (int y = 0; y < a.map.height(); ++y)
      for (int x = 0; x < a.map.width(); ++x) a.map.at(x, y, 0) = scale * float(1 + x + y * i);
    for (std::size_t t = 0; t < a.map.values().size(); ++t) root.map.values()[t] += a.map.values()[t];
    root.position += 0.25f * a.position;
    fine.apls.push_back(std::move(a));
  }
  coarse.apls.push_back(std::move(root));
  set.levels = {std::move(coarse), std::move(fine)};
  update_fluxes(set);
  set.bounds = bounding_sphere_of(set);
  return set;
}

}  // namespace

// A bundle is a folder of payloads and a manifest, written into a scratch folder and swapped in: a failure
// before the swap leaves the previous bundle whole and readable, one after it (the parent folder's sync)
// the new one, and neither leaves a scratch folder.
TEST(SyscallFaults, BundleWritesFailingAnywhereKeepThePreviousBundle) {
  const fs::path d = fresh_dir("bundle");
  const fs::path target = d / "lamp.lumx";
  const AplSet a = small_set(1), b = small_set(3);
  auto write_new = [&] { write_bundle(target.string(), b); };
  write_bundle(target.string(), a);
  const std::string old_manifest = slurp(target / "manifest.json");
  const std::uint64_t total = bytes_of(write_new);
  write_bundle(target.string(), a);
  ASSERT_GT(total, 1000u);
  auto expect_intact = [&](const std::string& what, const std::string& step, const std::string& why) {
    EXPECT_NE(what.find(target.string()), std::string::npos) << why << ": " << what;
    EXPECT_NE(what.find(step), std::string::npos) << why << ": " << what;
    EXPECT_EQ(slurp(target / "manifest.json"), old_manifest) << why;
    EXPECT_TRUE(check_bundle(target.string()).empty()) << why;
    EXPECT_TRUE(leftovers(d, target).empty()) << why;
  };
  const std::uint64_t stride = total / 97 + 1;
  for (std::uint64_t k = 0; k < total; k += stride) {
    expect_intact(failure_of({Call::write, ENOSPC, k}, write_new), std::strerror(ENOSPC),
                  "ENOSPC at byte " + std::to_string(k));
    if (HasFailure()) break;
  }
  expect_intact(failure_of({Call::write, EIO, total - 1}, write_new), std::strerror(EIO), "EIO at the last byte");
  expect_intact(failure_of({Call::fsync_file, EIO}, write_new), "fsync", "fsync of a payload");
  expect_intact(failure_of({Call::close_file, EIO}, write_new), "close", "close of a payload");
  // Each folder sync in turn (the payloads' folder after each payload, the scratch bundle's folders, the
  // parent after the swap) failing with EIO (EINVAL, a file system that cannot sync folders, is accepted):
  // an error naming the bundle, and either the previous bundle or, once swapped in, the new one, whole.
  int syncs = 0;
  {
    Armed count_them(Fault{});
    write_new();
    syncs = lumx_faults::directory_syncs();
  }
  write_bundle(target.string(), a);
  ASSERT_GE(syncs, 4);
  const std::string new_manifest = [&] {
    const fs::path other = d / "other";
    fs::create_directories(other);
    write_bundle((other / "lamp.lumx").string(), b);
    const std::string m = slurp(other / "lamp.lumx" / "manifest.json");
    fs::remove_all(other);
    return m;
  }();
  for (int k = 1; k <= syncs; ++k) {
    Fault f{Call::fsync_directory, EIO};
    f.nth = k;
    const std::string what = failure_of(f, write_new);
    const std::string why = "folder sync " + std::to_string(k) + " of " + std::to_string(syncs);
    EXPECT_NE(what.find(target.string()), std::string::npos) << why << ": " << what;
    EXPECT_NE(what.find("fsync folder"), std::string::npos) << why << ": " << what;
    const std::string now = slurp(target / "manifest.json");
    EXPECT_TRUE(now == old_manifest || now == new_manifest) << why;
    EXPECT_TRUE(check_bundle(target.string()).empty()) << why;
    EXPECT_TRUE(leftovers(d, target).empty()) << why;
    if (k == syncs) {  // the last is the parent's, after the swap: the new bundle is in place
      EXPECT_EQ(now, new_manifest) << why;
      EXPECT_NE(what.find("new version is in place"), std::string::npos) << why << ": " << what;
    }
    write_bundle(target.string(), a);
  }
  // Errors name the payload inside the bundle that was asked for, not the scratch folder.
  const std::string what = failure_of({Call::write, ENOSPC, 0}, write_new);
  EXPECT_EQ(what.rfind(target.string() + "/levels/level00_", 0), 0u) << what;
  EXPECT_EQ(what.find(".tmp-"), std::string::npos) << what;
  EXPECT_EQ(failure_of(Fault{}, write_new), "");
  EXPECT_NE(slurp(target / "manifest.json"), old_manifest);
  EXPECT_TRUE(check_bundle(target.string()).empty());
  fs::remove_all(d);
}

// write_file_atomically syncs the folder after the rename: if that fails the error is reported, and the
// file already holds the whole new version (old or new bytes only, never a mixture).
TEST(SyscallFaults, FailedFolderSyncReportsAndLeavesTheWholeNewFile) {
  const fs::path d = fresh_dir("dirsync");
  const fs::path target = d / "l.ies";
  write_photometry(table(1), target.string());
  const std::string what = failure_of({Call::fsync_directory, EIO}, [&] { write_photometry(table(2), target.string()); });
  EXPECT_NE(what.find("fsync folder"), std::string::npos) << what;
  EXPECT_NE(what.find("the new version is in place"), std::string::npos) << what;
  EXPECT_NE(what.find(target.string()), std::string::npos) << what;
  write_photometry(table(2), (d / "fresh.ies").string());
  EXPECT_EQ(slurp(target), slurp(d / "fresh.ies"));
  fs::remove(d / "fresh.ies");
  EXPECT_TRUE(leftovers(d, target).empty());
  fs::remove_all(d);
}
