#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Installs the Khronos glTF-Validator (npm package gltf-validator, pinned) into out/tools/ with the machine's
# Node.js and npm, for BakeGltfWriter.OutputPassesTheKhronosValidator. Never committed. Without Node.js or a
# reachable npm registry it says so and exits 0 (the test then skips, except under CI, where it fails).
set -uo pipefail
cd "$(dirname "$0")/.."
version=2.0.0-dev.3.10
dir=out/tools
if grep -q "\"version\": \"$version\"" "$dir/node_modules/gltf-validator/package.json" 2>/dev/null; then exit 0; fi
if ! command -v npm > /dev/null || ! command -v node > /dev/null; then
  echo "lumx: no Node.js/npm: the glTF-Validator test will be skipped" >&2
  exit 0
fi
mkdir -p "$dir"
npm install --prefix "$dir" --no-audit --no-fund --no-save "gltf-validator@$version" > "$dir/npm.log" 2>&1 ||
  echo "lumx: npm could not install gltf-validator@$version (see $dir/npm.log)" >&2
exit 0
