#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Installs the Debian 12 packages lumx builds against, if any is missing (needs root or sudo).
# Usage: scripts/deps.sh [PACKAGE...]   further packages a build needs (the sanitizer and fuzz builds: clang)
set -euo pipefail
PKGS=(build-essential cmake ninja-build pkg-config
      libglm-dev nlohmann-json3-dev libcli11-dev libgtest-dev libbenchmark-dev
      libcairo2-dev fonts-dejavu-core libopenexr-dev libssl-dev libxml2-dev libzip-dev
      libdraco-dev libembree-dev libtbb-dev
      python3 python3-jsonschema
      pybind11-dev python3-pybind11 python3-numpy python3-pytest "$@")
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "lumx: installing missing Debian packages: ${missing[*]}"
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
