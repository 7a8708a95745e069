// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Parse + flux throughput on real photometry files (Google Benchmark).
//
//   build/bench/lumx_bench_photometry [--benchmark_filter=...]
//
// "all_shared_files" reads every IES and EULUMDAT file under ../shared/data/photometry from memory,
// parses it and integrates its flux; bytes_per_second is the parse + flux rate over their total size.
// "lookup" measures one bilinear intensity query on the sample downlight, for reference.
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace {

struct InputFile {
  std::string name, text;
  bool ies;
};

std::vector<InputFile> load_shared() {
  std::vector<InputFile> out;
  const char* env = std::getenv("LUMX_SHARED_DIR");
  const std::filesystem::path root = std::filesystem::path(env && *env ? env : LUMX_SHARED_DIR_DEFAULT) / "data/photometry";
  if (!std::filesystem::exists(root)) return out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext != ".ies" && ext != ".ldt") continue;
    std::ifstream f(e.path(), std::ios::binary);
    std::ostringstream ss;
    ss << f.rdbuf();
    out.push_back({e.path().string(), ss.str(), ext == ".ies"});
  }
  std::sort(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.name < b.name; });
  return out;
}

void all_shared_files(benchmark::State& state) {
  static const std::vector<InputFile> files = load_shared();
  if (files.empty()) {
    state.SkipWithError("../shared/data/photometry not found (set LUMX_SHARED_DIR)");
    return;
  }
  std::size_t bytes = 0, parsed = 0;
  for (auto _ : state) {
    double sum = 0;
    for (const auto& f : files) {
      try {
        const lumx::Photometry p = f.ies ? lumx::read_ies(f.text, f.name) : lumx::read_ldt(f.text, f.name);
        sum += lumx::IntensityTable(p).flux_lm();
        ++parsed;
      } catch (const std::exception&) {
        // the intentionally invalid file
      }
      bytes += f.text.size();
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(static_cast<int64_t>(bytes));
  state.counters["files"] = static_cast<double>(files.size());
  state.counters["files_per_s"] = benchmark::Counter(static_cast<double>(parsed), benchmark::Counter::kIsRate);
}
BENCHMARK(all_shared_files)->Unit(benchmark::kMillisecond);

void lookup(benchmark::State& state) {
  const lumx::Photometry p = lumx::read_photometry(std::string(LUMX_SAMPLES_DIR) + "/downlight.ies");
  const lumx::IntensityTable t(p);
  std::mt19937 rng(1);
  std::normal_distribution<double> n;
  std::vector<glm::dvec3> dirs(4096);
  for (auto& d : dirs) d = {n(rng), n(rng), n(rng)};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(t.intensity(dirs[i++ & 4095]));
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(lookup);

}  // namespace

BENCHMARK_MAIN();
