#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# README command 1: build everything, then run the main job on what lumx generates itself (no data from
# elsewhere is needed), all into out/demo/:
#  0. four procedural glTF luminaires (samples/sample_luminaires.cpp); the troffer (three tubes behind a
#     prismatic refractor) baked: light particles traced through its geometry in passes until 5 % error
#     at d = 1 on held-out particles or 1 M particles -> a bundle with APL levels, held-out error tables,
#     radiance volume and far field; its table, plots, per-pass previews, far field as IES; the troffer
#     lighting a 3 x 3 x 2 m room with a table, rendered by particles (reference), its APL levels and its
#     far field, side by side with iso-lines, difference images and an error/time table;
#  1. a procedural 8-die LED strip written as a TM-25 rayset (samples/led_strip_rays.cpp) -> a lumx
#     bundle: APL levels by clustering, each level's error against the rays, the far field; prints the
#     speed-against-error table, writes its plots;
#  2. far-field photometry (info, check, IES -> LDT -> IES, polar plot);
#  3. the ring-luminaire embedding example (APL set + radiance volume by hand, partial loading).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$(bash scripts/build.sh | tail -n 1)
lumx="$dir/converters/lumx"
sample=samples/downlight.ies
out=out/demo
mkdir -p "$out"
lum=$out/luminaires
echo "== samples/sample_luminaires.cpp writes four glTF 2.0 luminaires -> $lum"
"$dir/samples/sample_luminaires" "$lum"
echo "== lumx info / check $lum/troffer.glb"
"$lumx" info "$lum/troffer.glb"
"$lumx" check "$lum/troffer.glb"
echo "== lumx bake $lum/troffer.glb -> $out/troffer.lumx (trace, APL levels, error tables, volume, far field)"
rm -rf "$out/troffer.lumx"
rm -rf "$out/troffer_preview"
"$lumx" bake "$lum/troffer.glb" "$out/troffer.lumx" --particles 1000000 --target-error 0.05 \
  --rays-out "$out/troffer_exits.tm25ray" --preview "$out/troffer_preview" | tee "$out/troffer_bake.txt"
"$lumx" check "$out/troffer.lumx"
"$lumx" eval "$out/troffer.lumx" --rays "$out/troffer_exits.tm25ray" --plots "$out/troffer_plots" > "$out/troffer_eval.txt"
"$lumx" convert "$out/troffer.lumx" "$out/troffer.ies"
"$lumx" plot "$out/troffer.ies" -o "$out/troffer_polar.png"
"$lumx" plot "$out/troffer.lumx" -o "$out/troffer_apls.svg"
echo "(plots in $out/troffer_plots, per-pass preview images and errors in $out/troffer_preview, far field"
echo " $out/troffer.ies and its polar plot, APL picture $out/troffer_apls.svg)"
echo "== lumx render room $out/troffer.lumx -> $out/troffer_room (reference, APL levels, LOD, far field)"
rm -rf "$out/troffer_room"
"$lumx" render room "$out/troffer.lumx" -o "$out/troffer_room" --luminaire-at 2.2 1.5 1.9 \
  --occluder 1.7 1.1 0.7 2.5 1.9 0.75 --particles 1000000 | tee "$out/troffer_room.txt"
echo "(reference | 512 APLs | far field side by side: $out/troffer_room/room_comparison.png; per method EXR,"
echo " iso-line PNG and difference image in $out/troffer_room)"
rays=$out/led_strip.tm25ray
echo "== samples/led_strip_rays.cpp writes a synthetic LED strip's rays -> $rays"
"$dir/samples/led_strip_rays" "$rays" --rays 200000 --seed 1
echo "== lumx info $rays"
"$lumx" info "$rays"
echo "== lumx build $rays -> $out/strip.lumx (APL levels, error tables, far field)"
rm -rf "$out/strip.lumx"
"$lumx" build "$rays" "$out/strip.lumx" | tee "$out/strip_build.txt"
"$lumx" check "$out/strip.lumx"
"$lumx" eval "$out/strip.lumx" --rays "$rays" --plots "$out/strip_plots" > "$out/strip_eval.txt"
echo "(error-against-distance, -time and -bytes plots in $out/strip_plots)"
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
