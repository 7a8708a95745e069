// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// SIGKILL during a write: a child process rewrites a file over and over (IES, EULUMDAT, TM-33 XML and
// JSON, TM-25, glTF luminaires as .glb and .gltf) and is killed while its temporary exists. The target must then hold one whole version,
// byte for byte, and the next write of the same target must leave no temporary behind
// (docs/robustness.md §4; hard-cases.md §6 item 36).
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>

#include "luminaire_test_scenes.h"
#include "test_support.h"

#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <functional>
#include <sstream>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("lumx_killed_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// Temporaries of `target` in its folder (temporary_sibling_name: ".NAME.tmp-PID-N").
std::vector<fs::path> temporaries_of(const fs::path& target) {
  std::vector<fs::path> out;
  const std::string prefix = "." + target.filename().string() + ".tmp-";
  for (const auto& e : fs::directory_iterator(target.parent_path()))
    if (e.path().filename().string().rfind(prefix, 0) == 0) out.push_back(e.path());
  return out;
}

/// Forks a child that calls write(k % 2) for k = 0, 1, 2, ... until it is killed, and kills it with SIGKILL
/// once one of its temporaries is seen. True if it died by SIGKILL and left a temporary behind (a kill that
/// lands just after a rename leaves none; the caller tries again).
bool kill_while_writing(const fs::path& target, const std::function<void(int)>& write) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    try {
      for (int k = 0;; ++k) write(k % 2);
    } catch (...) {
    }
    ::_exit(1);  // a write failed: the parent sees no SIGKILL
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  int status = 0;
  for (;;) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;
    if (!temporaries_of(target).empty() || std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL && !temporaries_of(target).empty();
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

/// The contract for one writer: after a SIGKILL the target is one of the two versions, whole; the next
/// write replaces it and removes the dead writer's temporary.
void expect_kill_leaves_a_whole_file(const fs::path& target, const std::function<void(int)>& write) {
  write(1);
  const std::string v1 = lumx_test::read_text(target);
  write(0);
  const std::string v0 = lumx_test::read_text(target);
  ASSERT_NE(v0, v1);
  ASSERT_GT(v0.size(), 200u << 10) << "too small to be caught mid-write";
  bool killed = false;
  for (int attempt = 0; attempt < 10 && !killed; ++attempt) killed = kill_while_writing(target, write);
  ASSERT_TRUE(killed) << "the writer was never caught with its temporary";
  const std::string after = lumx_test::read_text(target);
  EXPECT_TRUE(after == v0 || after == v1) << "a killed write left " << after.size() << " bytes, neither version ("
                                          << v0.size() << " or " << v1.size() << ")";
  EXPECT_FALSE(temporaries_of(target).empty());  // what SIGKILL left behind

  write(1);
  EXPECT_EQ(lumx_test::read_text(target), v1);
  EXPECT_TRUE(temporaries_of(target).empty()) << temporaries_of(target).front();
}

/// A full-sphere table on a `step` degree grid: at 0.5 degrees (721 C-planes x 361 gamma angles, the
/// EULUMDAT maximum) ~2 MB as IES text; `scale` makes a second version with other bytes.
Photometry big_table(double scale, double step) {
  const int nv = static_cast<int>(180 / step) + 1, nh = static_cast<int>(360 / step) + 1;
  std::ostringstream s;
  s << "IESNA:LM-63-2002\n[TEST] kill\n[MANUFAC] lumx tests\nTILT=NONE\n1 -1 1 " << nv << ' ' << nh
    << " 1 2 0 0 0\n1 1 10\n";
  for (int i = 0; i < nv; ++i) s << step * i << (i % 10 == 9 ? '\n' : ' ');
  s << '\n';
  for (int i = 0; i < nh; ++i) s << step * i << (i % 10 == 9 ? '\n' : ' ');
  s << '\n';
  for (int h = 0; h < nh; ++h) {
    for (int v = 0; v < nv; ++v) {
      const double c = h == nh - 1 ? 0 : h;  // C360 equals C0
      s << scale * (1000.5 + 0.25 * c + 400 * std::cos(v * step * M_PI / 180)) << (v % 10 == 9 ? '\n' : ' ');
    }
    s << '\n';
  }
  return read_ies(s.str(), "big.ies");
}

/// IES and EULUMDAT on the 0.5 degree grid; TM-33, whose writer builds an element tree, on a 2 degree
/// grid (still ~0.5 MB) to keep the test short.
void expect_photometry_kill(const std::string& name, double step) {
  const fs::path d = fresh_dir(name);
  const fs::path target = d / name;
  const Photometry a = big_table(1, step), b = big_table(2, step);
  expect_kill_leaves_a_whole_file(target, [&](int version) { write_photometry(version ? b : a, target.string()); });
  fs::remove_all(d);
}

}  // namespace

TEST(Robustness, KilledIesWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) { expect_photometry_kill("l.ies", 0.5); }
TEST(Robustness, KilledLdtWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) { expect_photometry_kill("l.ldt", 0.5); }
TEST(Robustness, KilledTm33XmlWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) { expect_photometry_kill("l.xml", 2); }
TEST(Robustness, KilledTm33JsonWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) { expect_photometry_kill("l.json", 2); }

TEST(Robustness, KilledTm25WriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) {
  // 200 000 rays, 5.6 MB: streamed through a 4 MiB buffer, so the temporary exists across several writes.
  const fs::path d = fresh_dir("tm25");
  const fs::path target = d / "rays.tm25ray";
  RayChunk rays;
  const std::size_t n = 200000;
  rays.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float t = static_cast<float>(i) * 1e-3f;
    rays.push_back({std::cos(t) * 0.01f, std::sin(t) * 0.01f, 0}, {0, 0, -1}, 1e-3f);
  }
  RaysetInfo info;
  info.format = "TM-25";
  expect_kill_leaves_a_whole_file(target, [&](int version) {
    RayChunk r = rays;
    if (version) r.flux.assign(n, 2e-3f);
    MemoryRaySource source(std::move(r), info);
    write_tm25(target.string(), info, source);
  });
  fs::remove_all(d);
}

namespace {

/// A luminaire of 47 600 triangles (120 rings × 200 sectors) as glTF: 4.0 MB as .glb, 5.3 MB as .gltf.
void write_sphere_luminaire(const fs::path& target, double albedo, bool binary) {
  lumx_test::write_white_sphere_luminaire(target, 120, 200, albedo, binary);
}

}  // namespace

TEST(Robustness, KilledGlbWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) {
  const fs::path d = fresh_dir("glb");
  const fs::path target = d / "luminaire.glb";
  expect_kill_leaves_a_whole_file(target, [&](int version) { write_sphere_luminaire(target, version ? 0.5 : 0.8, true); });
  fs::remove_all(d);
}

TEST(Robustness, KilledGltfWriteLeavesAWholeFileAndNoTemporaryAfterTheNextWrite) {
  const fs::path d = fresh_dir("gltf");
  const fs::path target = d / "luminaire.gltf";
  expect_kill_leaves_a_whole_file(target, [&](int version) { write_sphere_luminaire(target, version ? 0.5 : 0.8, false); });
  fs::remove_all(d);
}
