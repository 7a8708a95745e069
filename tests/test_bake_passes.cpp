// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx::bake::bake_luminaire (lumx/bake/bake.h): passes that do not change the bundle, the held-out stopping
// rule, the time budget, progress, and a bake killed with SIGKILL leaving the previous bundle whole.
#include "cli_test_support.h"
#include "luminaire_test_scenes.h"
#include "test_support.h"

#include <lumx/bake/bake.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/io/bundle_io.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <thread>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

using namespace lumx_test;
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) { return lumx_test::fresh_temp_dir("lumx_bake_passes_" + name); }

lumx::bake::BakeOptions small_bake(std::uint64_t particles) {
  lumx::bake::BakeOptions o;
  o.particles = particles;
  o.volume_voxels = 4096;
  o.bundle.apl.level_counts = {1, 8};
  o.bundle.apl.seed_rays = 20000;
  // The sanitizer build grades R 32 maps: its fit and kernels run the same code as at R 128, and this test
  // takes 62 s there instead of 300 s.
  if (lumx_test::kSanitized) o.bundle.apl.max_resolution = 32;
  return o;
}

std::string attachment_sha(const lumx::BundleReader& b, const std::string& name) {
  for (const auto& [a, payload] : b.manifest().attachments)
    if (a.name == name) return payload.sha256;
  return {};
}

TEST(BakePasses, SameBundleForAnyPassSizeAndThreadCount) {
  const fs::path dir = scratch("determinism");
  const fs::path glb = write_sphere_luminaire(dir);
  struct Variant {
    std::uint64_t pass;
    int threads;
    std::size_t passes;
  };
  const std::vector<Variant> variants = {{0, 1, 1}, {4096, 2, 5}, {7001, 2, 3}};
  for (std::size_t v = 0; v < variants.size(); ++v) {
    lumx::bake::BakeOptions o = small_bake(20000);
    o.pass_particles = variants[v].pass;
    o.threads = variants[v].threads;
    o.bundle.evaluate = false;
    o.rays_out = (dir / ("r" + std::to_string(v) + ".tm25ray")).string();
    const auto r = lumx::bake::bake_luminaire(glb.string(), (dir / ("b" + std::to_string(v))).string(), o);
    EXPECT_EQ(r.passes.size(), variants[v].passes) << v;
    EXPECT_EQ(r.counters.emitted, 20000u);
    EXPECT_EQ(r.stopped_by, "particle budget");
  }
  const lumx::BundleReader first((dir / "b0").string());
  ASSERT_TRUE(first.manifest().volume.has_value());
  for (std::size_t v = 1; v < variants.size(); ++v) {
    const lumx::BundleReader other((dir / ("b" + std::to_string(v))).string());
    EXPECT_EQ(read_text(dir / "r0.tm25ray"), read_text(dir / ("r" + std::to_string(v) + ".tm25ray"))) << v;
    ASSERT_EQ(first.manifest().levels.size(), other.manifest().levels.size());
    for (std::size_t k = 0; k < first.manifest().levels.size(); ++k)
      EXPECT_EQ(first.manifest().levels[k].maps.at(0).sha256, other.manifest().levels[k].maps.at(0).sha256) << v;
    EXPECT_EQ(first.manifest().volume->payload.sha256, other.manifest().volume->payload.sha256) << v;
    EXPECT_EQ(attachment_sha(first, "far_field.ies"), attachment_sha(other, "far_field.ies")) << v;
    EXPECT_EQ(attachment_sha(first, "luminaire.glb"), attachment_sha(other, "luminaire.glb")) << v;
  }
  // No scratch file of exits is left beside the bundles.
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  fs::remove_all(dir);
}

TEST(BakePasses, StopsAsSoonAsTheHeldOutErrorIsBelowTheTarget) {
  const fs::path dir = scratch("target");
  const fs::path glb = write_disk_luminaire(dir);
  std::vector<lumx::bake::BakeProgress> seen;
  lumx::bake::BakeOptions o = small_bake(4000000);
  o.target_error = 0.5;  // 50 % at d = 2: reached by the first pass of 2^18 particles
  o.target_distance = 2;
  o.progress = [&](const lumx::bake::BakeProgress& p) { seen.push_back(p); };
  const auto r = lumx::bake::bake_luminaire(glb.string(), (dir / "easy").string(), o);
  ASSERT_EQ(r.passes.size(), 1u);
  EXPECT_TRUE(r.target_met);
  EXPECT_EQ(r.stopped_by, "target error");
  EXPECT_EQ(r.counters.emitted, std::uint64_t(1) << 18);
  const lumx::bake::BakePass& p = r.passes[0];
  ASSERT_TRUE(p.graded);
  EXPECT_LE(p.error, 0.5);
  EXPECT_GE(p.error, p.error_estimate);  // the rule stops on the upper bound, not the estimate
  ASSERT_EQ(p.level_error.size(), 2u);
  // The bundle stores the very grading the rule stopped on, and records the error reached.
  EXPECT_TRUE(r.bundle.error_tables_stored);
  const lumx::BundleReader easy((dir / "easy").string());
  EXPECT_EQ(easy.manifest().provenance.at("stopped_by"), "target error");
  EXPECT_NEAR(std::stod(easy.manifest().provenance.at("error_reached")), p.error, 1e-6);
  const auto passes = nlohmann::json::parse(easy.manifest().provenance.at("passes"));
  ASSERT_EQ(passes.size(), 1u);
  EXPECT_EQ(passes[0]["particles"].get<std::uint64_t>(), std::uint64_t(1) << 18);
  // Progress: tracing then grading, particles never decreasing, the error known after the grading.
  bool traced = false, graded = false;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    traced |= std::string(seen[i].phase) == "tracing";
    graded |= std::string(seen[i].phase) == "grading";
    if (i > 0) {
      EXPECT_GE(seen[i].particles, seen[i - 1].particles);
    }
  }
  EXPECT_TRUE(traced && graded);
  EXPECT_TRUE(std::isfinite(seen.back().error));

  // A target below what 600 000 particles can show: the budget ends the bake, passes growing to it. (The
  // sanitizer build's 400 000 still make two passes, the second 1.5 times the first.)
  o.particles = lumx_test::kSanitized ? 400000 : 600000;
  o.target_error = 1e-4;
  o.progress = nullptr;
  const auto hard = lumx::bake::bake_luminaire(glb.string(), (dir / "hard").string(), o);
  EXPECT_FALSE(hard.target_met);
  EXPECT_EQ(hard.stopped_by, "particle budget");
  ASSERT_GE(hard.passes.size(), 2u);
  for (std::size_t i = 1; i < hard.passes.size(); ++i) {
    EXPECT_GE(hard.passes[i].particles, hard.passes[i - 1].particles * 3 / 2 - 1) << i;  // growth ≥ 1.5×, or
    EXPECT_TRUE(hard.passes[i].graded);                                                // the budget's end
  }
  EXPECT_EQ(hard.passes.back().particles, o.particles);
  EXPECT_EQ(hard.counters.emitted, o.particles);
  fs::remove_all(dir);
}

TEST(BakePasses, TimeLimitEndsTheBakeBeforeTheBudget) {
  const fs::path dir = scratch("time");
  const fs::path glb = write_sphere_luminaire(dir);
  lumx::bake::BakeOptions o = small_bake(std::uint64_t(1) << 34);  // far more than 0.5 s can trace
  o.pass_particles = 8192;
  o.time_limit_seconds = 0.5;
  o.bundle.evaluate = false;
  const auto r = lumx::bake::bake_luminaire(glb.string(), (dir / "b").string(), o);
  EXPECT_EQ(r.stopped_by, "time limit");
  EXPECT_LT(r.counters.emitted, o.particles);
  EXPECT_GE(r.counters.emitted, 8192u);
  EXPECT_EQ(r.counters.emitted, r.passes.back().particles);
  EXPECT_EQ(lumx::BundleReader((dir / "b").string()).manifest().provenance.at("stopped_by"), "time limit");
  fs::remove_all(dir);
}

TEST(BakePasses, BadOptionsAreNamed) {
  const fs::path dir = scratch("options");
  const fs::path glb = write_disk_luminaire(dir);
  lumx::bake::BakeOptions o = small_bake(0);
  try {
    lumx::bake::bake_luminaire(glb.string(), (dir / "b").string(), o);
    FAIL() << "a zero particle budget was accepted";
  } catch (const lumx::Error& e) {
    EXPECT_EQ(e.diagnostic().field, "particles");
  }
  o.particles = 1000;
  o.target_error = std::nan("");
  EXPECT_THROW(lumx::bake::bake_luminaire(glb.string(), (dir / "b").string(), o), lumx::Error);
  EXPECT_FALSE(fs::exists(dir / "b"));
  fs::remove_all(dir);
}

/// Runs `lumx bake` in a child process and kills it with SIGKILL as soon as `ready` says so (or lets it
/// finish); returns true if it was killed.
bool bake_and_kill(const std::vector<std::string>& args, const std::function<bool()>& ready) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string cli = LUMX_CLI_PATH;
    argv.push_back(cli.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(cli.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  for (;;) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // finished first
    if (ready()) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

bool has_entry_containing(const fs::path& dir, const std::string& part) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(part) != std::string::npos) return true;
  return false;
}

TEST(BakePasses, KilledBakeLeavesThePreviousBundleAndNoScratchAfterTheNextRun) {
  if (std::string(LUMX_CLI_PATH).empty()) GTEST_SKIP() << "built without the CLI";
  const fs::path dir = scratch("kill");
  const fs::path glb = write_sphere_luminaire(dir);
  const std::string out = (dir / "b").string();
  const std::vector<std::string> small = {"bake", glb.string(), out, "--particles", "20000", "--levels", "1", "8",
                                          "--no-eval", "--volume-voxels", "4096"};
  ASSERT_FALSE(bake_and_kill(small, [] { return false; }));
  const std::string manifest = read_text(dir / "b" / "manifest.json");
  ASSERT_FALSE(manifest.empty());

  // Killed while tracing (its scratch file of exits exists), then while writing the new bundle (its
  // temporary folder exists).
  const std::vector<std::string> big = {"bake", glb.string(), out, "--particles", "60000", "--levels", "1", "8",
                                        "--no-eval", "--volume-voxels", "4096", "--threads", "1"};
  EXPECT_TRUE(bake_and_kill(big, [&] { return has_entry_containing(dir, ".b.exits.tmp-"); }));
  bool killed_writing = false;
  for (int attempt = 0; attempt < 5 && !killed_writing; ++attempt)
    killed_writing = bake_and_kill(big, [&] { return has_entry_containing(dir, ".b.tmp-"); });
  EXPECT_TRUE(killed_writing) << "the bake was never caught writing its bundle";
  EXPECT_TRUE(has_entry_containing(dir, ".tmp-"));  // what SIGKILL left behind
  EXPECT_EQ(read_text(dir / "b" / "manifest.json"), manifest);
  EXPECT_TRUE(lumx::check_bundle(out).empty());  // every payload read, sizes and SHA-256 verified

  // The next bake of the same bundle removes the dead bakes' scratch files and temporaries.
  ASSERT_FALSE(bake_and_kill(small, [] { return false; }));
  EXPECT_FALSE(has_entry_containing(dir, ".tmp-"));
  EXPECT_TRUE(lumx::check_bundle(out).empty());
  fs::remove_all(dir);
}

}  // namespace
