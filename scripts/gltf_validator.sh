#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Installs the Khronos glTF-Validator (npm package gltf-validator) into out/tools/ with the machine's Node.js
# and npm, for BakeGltfWriter.OutputPassesTheKhronosValidator: `npm ci` from tests/tools/npm/, whose lock file
# pins the version and its SHA-512. Never committed. Without Node.js or a reachable npm registry it says so
# and exits 0 (the test then skips, except under CI, where it fails).
set -uo pipefail
cd "$(dirname "$0")/.."
dir=out/tools
if cmp -s tests/tools/npm/package-lock.json "$dir/package-lock.json" && [ -f "$dir/node_modules/gltf-validator/package.json" ]; then
  exit 0
fi
if ! command -v npm > /dev/null || ! command -v node > /dev/null; then
  echo "lumx: no Node.js/npm: the glTF-Validator test will be skipped" >&2
  exit 0
fi
mkdir -p "$dir"
cp tests/tools/npm/package.json tests/tools/npm/package-lock.json "$dir/"
npm ci --prefix "$dir" --no-audit --no-fund > "$dir/npm.log" 2>&1 ||
  echo "lumx: npm could not install the glTF-Validator (see $dir/npm.log)" >&2
exit 0
