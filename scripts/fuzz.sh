#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Builds the libFuzzer targets (clang, ASan + UBSan, coverage from the library itself) into build-fuzz/ and
# runs them, each for SECONDS, with its dictionary (tests/fuzz/dict/<target>.dict).
# Usage: scripts/fuzz.sh [TARGET|all] [SECONDS]   targets: photometry rayset gltf bundle gldf (default 60 s)
#        scripts/fuzz.sh --ci [SECONDS]           CI: every target SECONDS (default 20 s) on a fresh corpus
# LUMX_FUZZ_TIMEOUT (seconds, default 25): the time one input may take; raise it for offline runs on a machine
# that is busy with other work (a starved run reports timeouts that are not findings).
# Offline runs start from the project's seeds (tests/data/fuzz/, tests/data/bad/, tests/data/ldt/,
# tests/data/tm33/, samples/, the generated sample luminaires) plus ../shared/data files of the target's
# kind, copied into out/fuzz/<target>/corpus/ (never into the repository); the corpus grows run after run.
# --ci uses the repository's seeds only, so a finding can be replayed from committed files, builds in
# build-fuzz-ci/ at -O1 with line tables only (as OSS-Fuzz does; a quarter less compile time), runs as many
# targets at once as there are cores, runs every target even after a finding, and exits non-zero if any
# target found a crash, a leak, a timeout (25 s) or an out-of-memory (2 GiB).
# A crash is saved under out/fuzz/<target>/artifacts/ (--ci: out/fuzz/ci/<target>/artifacts/, beside its log,
# so that a CI run never mixes with an offline one); once fixed, copy it to tests/data/fuzz/<target>/ so that
# CTest replays it (fuzz_replay.<target>) in every build.
set -euo pipefail
cd "$(dirname "$0")/.."
ci=0
if [ "${1:-}" = "--ci" ]; then ci=1; shift; set -- all "${1:-20}"; fi
which=${1:-all}
seconds=${2:-60}
bash scripts/deps.sh clang libclang-rt-dev >&2
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
bdir=build-fuzz; flags=()
if [ $ci = 1 ]; then bdir=build-fuzz-ci; flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG"); fi
start=$(date +%s)
cmake -S . -B "$bdir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DLUMX_BUILD_FUZZERS=ON -DLUMX_BUILD_TESTS=OFF -DLUMX_BUILD_BENCH=OFF -DLUMX_BUILD_CLI=OFF \
  -DLUMX_BUILD_SAMPLES=OFF -DLUMX_WERROR=OFF "${flags[@]}" "${launcher[@]}" >&2
targets=(photometry rayset gltf bundle gldf)
[ "$which" != all ] && targets=("$which")
cmake --build "$bdir" -j "$(nproc)" --target $(printf 'lumx_fuzz_%s ' "${targets[@]}") >&2
echo "== fuzz targets built in $(( $(date +%s) - start )) s"

shared=../shared/data
lum=out/fuzz/luminaires
if [ ! -d "$lum" ] && [ -x build/samples/sample_luminaires ]; then build/samples/sample_luminaires "$lum" > /dev/null; fi
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$(pwd)/scripts/lsan.supp"
# Offline runs keep their corpora, logs and artifacts in out/fuzz/<target>/, CI runs in out/fuzz/ci/<target>/.
out=out/fuzz
[ $ci = 1 ] && out=out/fuzz/ci
# One target: seeds into its corpus, then libFuzzer; the exit status goes to $out/<target>/status.
run_target() {
  local t=$1 corpus=$out/$t/corpus max_len
  [ $ci = 1 ] && rm -rf "$corpus"
  mkdir -p "$corpus" "$out/$t/artifacts"
  # Seed names: the path with '/' as '_' and no leading dots (hidden files would not be counted).
  seed() { for f in "$@"; do [ -f "$f" ] && cp -n "$f" "$corpus/$(echo "$f" | tr '/' '_' | sed 's/^[._]*//')" 2>/dev/null || true; done; }
  case $t in
    photometry) seed tests/data/bad/* tests/data/ldt/* tests/data/tm33/* samples/*.ies
                [ $ci = 0 ] && [ -d "$shared" ] && while IFS= read -r f; do seed "$f"; done < <(find "$shared/photometry" -iname '*.ies' -o -iname '*.ldt' | head -200)
                max_len=65536 ;;
    rayset)     [ $ci = 0 ] && [ -d "$shared" ] && while IFS= read -r f; do seed "$f"; done < <(find "$shared/raysets" -size -400k -type f 2>/dev/null | head -50)
                max_len=262144 ;;
    gltf)       seed "$lum"/troffer.glb "$lum"/pendant.glb
                max_len=262144 ;;
    *)          max_len=65536 ;;
  esac
  [ -d "tests/data/fuzz/$t" ] && seed tests/data/fuzz/"$t"/*
  local status=0
  "$bdir"/tests/fuzz/lumx_fuzz_"$t" "$corpus" -dict="tests/fuzz/dict/$t.dict" -max_total_time="$seconds" \
    -max_len="$max_len" -timeout="${LUMX_FUZZ_TIMEOUT:-25}" -rss_limit_mb=2048 -artifact_prefix="$out/$t/artifacts/" \
    -print_final_stats=1 > "$out/$t/log.txt" 2>&1 || status=$?
  echo "$status $(ls "$corpus" | wc -l)" > "$out/$t/status"
}

# Offline: one target after the other. CI: as many at once as there are cores (each keeps its SECONDS).
parallel=1
[ $ci = 1 ] && parallel=$(nproc)
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
  echo "== lumx_fuzz_$t: $seconds s"
  run_target "$t" &
done
wait
failed=()
for t in "${targets[@]}"; do
  log=$out/$t/log.txt
  read -r status corpus_files < "$out/$t/status"
  echo "== lumx_fuzz_$t: exit $status, corpus of $corpus_files files at the end"
  grep -E "^#[0-9]+ *(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss|ERROR|SUMMARY|Test unit written" \
    "$log" | tail -5 || true
  if [ "$status" -ne 0 ]; then
    failed+=("$t")
    echo "== lumx_fuzz_$t FAILED; the end of $log:"
    tail -60 "$log"
  fi
done
echo "== fuzzing took $(( $(date +%s) - start )) s in all (build included)"
if [ ${#failed[@]} -ne 0 ]; then
  echo "== findings in: ${failed[*]} (inputs under $out/<target>/artifacts/)"
  exit 1
fi
