#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# README command 2: build and run the whole test suite. Usage: scripts/test.sh [--sanitize]
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$(bash scripts/build.sh "$@" | tail -n 1)
bash scripts/gltf_validator.sh  # the Khronos glTF-Validator for the glTF writer's test (npm, into out/tools/)
# The sanitized run leaves out the accuracy tier (tests/tiers.cmake): its statistics and real-file sweeps
# run at several times their cost under the sanitizers and exercise code the other tiers already run there;
# the release run (the README's command) runs every tier. Each tier is a CTest label.
labels=()
if [ "${1:-}" = "--sanitize" ]; then
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  export LSAN_OPTIONS="suppressions=$(pwd)/scripts/lsan.supp"
  labels=(-LE accuracy)
fi
ctest --test-dir "$dir" --output-on-failure -j "$(nproc)" "${labels[@]}"
