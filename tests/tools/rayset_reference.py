#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Independent reference figures for a ray file, for tests/test_rayset_read.cpp.

Standard library only (struct, math, json). Written from the format descriptions (docs/rays.md,
../shared/docs/formats.md §3), not from lumx's C++ code, so the two can check each other:
  - TM-25: the ray block is located from the END of the file (n rays x columns x 4 bytes), not by walking
    the preamble as the C++ reader does.
  - LightTools binary: rays between the 44-byte header and the trailing "LTRFEND".
  - Zemax binary: 208-byte header, count from the header.
  - LightTools text, Zemax text, lumx plain text: parsed line by line.
Prints one JSON object: format, rays, quantity, header_flux (null if not stated), flux_sum (math.fsum),
bounding box lo/hi and bounding-sphere radius (about the box centre) of the start points in metres.

Usage: rayset_reference.py FILE
"""
import json
import math
import os
import struct
import sys

LENGTH_M = {  # metres per unit
    "mm": 1e-3, "millimeters": 1e-3, "cm": 1e-2, "centimeters": 1e-2, "m": 1.0, "meters": 1.0,
    "in": 0.0254, "inches": 0.0254, "ft": 0.3048, "feet": 0.3048, "um": 1e-6, "microns": 1e-6,
    "nm": 1e-9, "nanometers": 1e-9,
}
ZEMAX_UNITS = {0: 1.0, 1: 0.0254, 2: 1e-2, 3: 0.3048, 4: 1e-3}
LIGHTTOOLS_UNITS = {1: 1e-3, 2: 1e-2, 3: 1.0, 4: 0.0254, 5: 0.3048, 6: 1e-6, 7: 1e-9}


def summary(fmt, quantity, header_flux, rays, scale):
    """rays: iterable of (x, y, z, flux) in file units; scale: metres per file unit."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    fluxes = []
    pts = []
    for x, y, z, f in rays:
        p = (x * scale, y * scale, z * scale)
        pts.append(p)
        fluxes.append(f)
        for k in range(3):
            lo[k] = min(lo[k], p[k])
            hi[k] = max(hi[k], p[k])
    c = [(lo[k] + hi[k]) / 2 for k in range(3)]
    r = max((math.sqrt(sum((p[k] - c[k]) ** 2 for k in range(3))) for p in pts), default=0.0)
    hf = None if header_flux is None or math.isnan(header_flux) else header_flux
    return {"format": fmt, "rays": len(pts), "quantity": quantity, "header_flux": hf,
            "flux_sum": math.fsum(fluxes), "lo": lo, "hi": hi, "radius": r}


def tm25(data):
    n = struct.unpack_from("<Q", data, 20)[0]
    phi_v, phi_e = struct.unpack_from("<ff", data, 12)
    n_add = struct.unpack_from("<i", data, 80)[0]
    pos, dirf, rad, lam, lum, stokes, tri, idx = struct.unpack_from("<8i", data, 256)
    cols = 6 + rad + lam + lum + 6 * stokes + 2 * tri + idx + n_add
    start = len(data) - n * cols * 4
    flux_col = 6 + rad + lam if lum else 6
    rays = ((r[0], r[1], r[2], r[flux_col])
            for r in struct.iter_unpack("<%df" % cols, data[start:]))
    if lum:
        return summary("TM-25", "photometric", phi_v, rays, 1e-3)
    return summary("TM-25", "radiometric", phi_e, rays, 1e-3)


def lighttools_binary(data):
    _, _, dtype, _, colour, units = struct.unpack_from("<6I", data, 4)
    total = struct.unpack_from("<f", data, 40)[0]
    cols = 8 if colour == 2 else 7
    assert data[-7:] == b"LTRFEND"
    body = data[44:-7]
    rays = ((r[0], r[1], r[2], r[6]) for r in struct.iter_unpack("<%df" % cols, body))
    return summary("LightTools binary", "photometric" if dtype == 1 else "radiometric", total, rays,
                   LIGHTTOOLS_UNITS[units])


def zemax_binary(data):
    n = struct.unpack_from("<I", data, 4)[0]
    set_flux = struct.unpack_from("<f", data, 112)[0]
    units = struct.unpack_from("<I", data, 136)[0]
    fmt, flux_type = struct.unpack_from("<ii", data, 192)
    cols = 8 if fmt == 2 else 7
    body = data[208:208 + n * cols * 4]
    rays = ((r[0], r[1], r[2], r[6]) for r in struct.iter_unpack("<%df" % cols, body))
    return summary("Zemax binary", "photometric" if flux_type == 1 else "radiometric", set_flux, rays,
                   ZEMAX_UNITS[units])


def numbers(line):
    return [float(t) for t in line.replace(",", " ").split()]


def lighttools_text(text):
    header = {}
    lines = text.splitlines()
    i = 0
    while lines[i].strip() != "lt_startofdata":
        s = lines[i].strip()
        if s and not s.startswith("#") and ":" in s:
            k, v = s.split(":", 1)
            header[k.strip()] = v.strip()
        i += 1
    rays = []
    for s in lines[i + 1:]:
        s = s.strip()
        if s == "lt_endofdata":
            break
        if s:
            v = numbers(s)
            rays.append((v[0], v[1], v[2], v[6]))
    radiant = "radi" in header.get("lt_datatype", "")
    key = "lt_radiant_flux" if radiant else "lt_luminous_flux"
    hf = float(header[key]) if key in header else None
    return summary("LightTools text", "radiometric" if radiant else "photometric", hf, rays,
                   LENGTH_M[header.get("lt_length_units", "mm")])


def zemax_text(text):
    lines = [s for s in text.splitlines() if s.strip()]
    head = numbers(lines[0])
    rays = [(v[0], v[1], v[2], v[6]) for v in map(numbers, lines[1:])]
    assert len(rays) == int(head[0])
    return summary("Zemax text", "radiometric", None, rays, ZEMAX_UNITS[int(head[1])])


def plain_text(text):
    lines = text.splitlines()
    keys = dict(item.split("=", 1) for item in lines[0].split()[2:])
    data = [numbers(s) for s in lines[1:] if s.strip() and not s.strip().startswith("#")]
    total = float(keys["total"]) if "total" in keys else None
    rays = []
    for v in data:
        f = v[6] if len(v) >= 7 else (total / len(data) if total is not None else 1.0)
        rays.append((v[0], v[1], v[2], f))
    return summary("plain text", "photometric" if keys["flux"] == "lm" else "radiometric", total, rays,
                   LENGTH_M[keys["length"]])


def main(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"TM25":
        out = tm25(data)
    elif data[:4] == b"LTRF":
        out = lighttools_binary(data)
    elif len(data) >= 208 and struct.unpack_from("<i", data, 0)[0] == 1010:
        out = zemax_binary(data)
    else:
        text = data.decode("utf-8", "replace")
        first = text.lstrip().splitlines()[0]
        if first.startswith("# lumx-rays"):
            out = plain_text(text)
        elif "lt_startofdata" in text:
            out = lighttools_text(text)
        else:
            out = zemax_text(text)
    out["file"] = os.path.basename(path)
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1])
