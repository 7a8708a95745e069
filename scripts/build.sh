#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Builds lumx (installing missing Debian packages first). Usage: scripts/build.sh [--sanitize]
#   default      -> build/        (RelWithDebInfo with -g1: line tables and function names for backtraces,
#                                  no variable locations, which cost a third of the compile time: one
#                                  test file 49.7 s with -g, 32.0 s with -g1; warnings as errors)
#   --sanitize   -> build-asan/   (Debug, AddressSanitizer + UndefinedBehaviorSanitizer; -g1: the reports'
#                                  stacks need line tables only; test_bundle.cpp 32.3 s with -g, 29.6 s
#                                  with -g1. -Og, as sanitizer builds are usually optimised a little: the
#                                  sanitized tests ran in 198 s against 554 s at -O0 (CTest's total
#                                  of scripts/test.sh --sanitize), its test files took
#                                  1 005 against 771 CPU-s to compile. clang compiles in 40 % less time,
#                                  but its -O0 code ran the numerical tests at half gcc's speed,
#                                  AplErrorLevels.ErrorDecreases… 38.9 against 18.9 s, and four tests
#                                  reached the 300 s timeout.)
set -euo pipefail
cd "$(dirname "$0")/.."
dir=build; extra=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG")
if [ "${1:-}" = "--sanitize" ]; then
  dir=build-asan; extra=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-g1 -Og" -DLUMX_SANITIZE=ON -DLUMX_BUILD_BENCH=OFF)
fi
bash scripts/deps.sh >&2
# Progress and errors go to stderr; stdout carries only the build folder, for the other scripts.
cmake -S . -B "$dir" -G Ninja "${extra[@]}" >&2
cmake --build "$dir" -j "$(nproc)" >&2
echo "$dir"
