#!/usr/bin/env bash
# README command 1: build everything, then run the main job on the bundled sample luminaires, all into
# out/demo/: far-field photometry (info, check, IES -> LDT -> IES, polar plot), and a lumx bundle (the
# ring luminaire sample's APL set and radiance volume: build, info, check, partial load and irradiance per
# level, far-field export, map and position plots).
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
echo "== lumx bundle: samples/ring_luminaire.cpp builds a 1/8/64-APL set and a radiance volume"
rm -rf "$out/ring.lumx"
"$dir/samples/ring_luminaire" "$out/ring.lumx" | tee "$out/ring.txt"
"$lumx" info "$out/ring.lumx" | tee "$out/ring_info.txt"
"$lumx" check "$out/ring.lumx"
"$lumx" convert "$out/ring.lumx" "$out/ring_level8.ldt" --level 1
"$lumx" plot "$out/ring.lumx" --level 1 --apl 0 -o "$out/ring_level8_apl0.png"
"$lumx" plot "$out/ring.lumx" -o "$out/ring_apls.svg"
echo "== lumx convert $sample -> one-APL bundle"
rm -rf "$out/downlight.lumx"
"$lumx" convert "$sample" "$out/downlight.lumx" --map-resolution 128
"$lumx" check "$out/downlight.lumx"
echo
echo "All outputs are in $(pwd)/$out"
