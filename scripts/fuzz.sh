#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Builds the libFuzzer targets (clang, ASan + UBSan, coverage from the library itself) into build-fuzz/ and
# runs them, each for SECONDS (default 60), on a corpus made at run time from the project's seeds
# (tests/data/fuzz/, tests/data/bad/, samples/, the generated sample luminaires) plus ../shared/data files
# of the target's kind, copied into a scratch corpus (never into the repository).
# Usage: scripts/fuzz.sh [TARGET|all] [SECONDS]     targets: photometry rayset gltf bundle
# A crash is saved under out/fuzz/<target>/artifacts/; once fixed, copy it to tests/data/fuzz/<target>/ so
# that CTest replays it (fuzz_replay.<target>) in every build.
set -euo pipefail
cd "$(dirname "$0")/.."
which=${1:-all}
seconds=${2:-60}
bash scripts/deps.sh >&2
dpkg-query -W -f='${Status}' clang libclang-rt-dev 2>/dev/null | grep -c 'install ok installed' | grep -q 2 || {
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-dev >&2
}
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DLUMX_BUILD_FUZZERS=ON -DLUMX_BUILD_TESTS=OFF -DLUMX_BUILD_BENCH=OFF -DLUMX_BUILD_CLI=OFF \
  -DLUMX_BUILD_SAMPLES=OFF -DLUMX_WERROR=OFF >&2
targets=(photometry rayset gltf bundle)
[ "$which" != all ] && targets=("$which")
cmake --build build-fuzz -j "$(nproc)" --target $(printf 'lumx_fuzz_%s ' "${targets[@]}") >&2

shared=../shared/data
lum=out/fuzz/luminaires
if [ ! -d "$lum" ] && [ -x build/samples/sample_luminaires ]; then build/samples/sample_luminaires "$lum" > /dev/null; fi
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$(pwd)/scripts/lsan.supp"
for t in "${targets[@]}"; do
  corpus=out/fuzz/$t/corpus
  mkdir -p "$corpus" "out/fuzz/$t/artifacts"
  # Seed names: the path with '/' as '_' and no leading dots (hidden files would not be counted).
  seed() { for f in "$@"; do [ -f "$f" ] && cp -n "$f" "$corpus/$(echo "$f" | tr '/' '_' | sed 's/^[._]*//')" 2>/dev/null || true; done; }
  case $t in
    photometry) seed tests/data/bad/* tests/data/ldt/* samples/*.ies
                [ -d "$shared" ] && while IFS= read -r f; do seed "$f"; done < <(find "$shared/photometry" -iname '*.ies' -o -iname '*.ldt' | head -200)
                max_len=65536 ;;
    rayset)     seed tests/data/fuzz/rayset/*
                [ -d "$shared" ] && while IFS= read -r f; do seed "$f"; done < <(find "$shared/raysets" -size -400k -type f 2>/dev/null | head -50)
                max_len=262144 ;;
    gltf)       seed tests/data/fuzz/gltf/* "$lum"/troffer.glb "$lum"/pendant.glb
                max_len=262144 ;;
    bundle)     seed tests/data/fuzz/bundle/*
                max_len=65536 ;;
  esac
  [ -d "tests/data/fuzz/$t" ] && seed tests/data/fuzz/"$t"/*
  echo "== lumx_fuzz_$t: $(ls "$corpus" | wc -l) seed files, $seconds s"
  build-fuzz/tests/fuzz/lumx_fuzz_"$t" "$corpus" -max_total_time="$seconds" -max_len="$max_len" -timeout=25 \
    -rss_limit_mb=2048 -artifact_prefix="out/fuzz/$t/artifacts/" -print_final_stats=1 2>&1 \
    | grep -E "^#[0-9]+ *(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss|cov:|ERROR|SUMMARY|Test unit written" \
    | tail -6
done
