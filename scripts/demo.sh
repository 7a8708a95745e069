#!/usr/bin/env bash
# README command 1: build everything, then run the main job on the bundled sample luminaire:
# info, check, convert IES -> LDT -> IES, and the polar plot, all into out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$(bash scripts/build.sh | tail -n 1)
lumx="$dir/converters/lumx"
sample=samples/downlight.ies
out=out/demo
mkdir -p "$out"
echo "== lumx info $sample"
"$lumx" info "$sample" | tee "$out/info.txt"
"$lumx" info --json "$sample" > "$out/info.json"
echo "== lumx check $sample"
"$lumx" check "$sample" | tee "$out/check.txt"
echo "== lumx convert $sample -> LDT -> IES"
"$lumx" convert "$sample" "$out/downlight.ldt"
"$lumx" convert "$out/downlight.ldt" "$out/downlight_roundtrip.ies"
"$lumx" check "$out/downlight.ldt" "$out/downlight_roundtrip.ies"
echo "== lumx plot"
"$lumx" plot "$sample" -o "$out/downlight_polar.svg"
"$lumx" plot "$sample" -o "$out/downlight_polar.png"
echo
echo "All outputs are in $(pwd)/$out"
