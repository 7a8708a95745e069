#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Charts `lumx build` (rays as lines, the default) against `lumx build --no-converge` on synthetic
luminaires, the study behind docs/apl_sets.md "Charted on synthetic luminaires".

Standard library only. For each geometry and seed it writes a plain-text rayset (docs/rays.md), builds
it both ways, and prints the relative RMSE (%) of every level at d = 0.5, 1, 2, 10 as
"default / --no-converge", the noise floor, and the builder's `lines:` figures (ratio against shuffled
directions, clustering choice).

Geometries (metres, 1000 lm each):
  sphere     frosted bulb: points on a 3 cm sphere, Lambertian about the outward normal
  panel      0.6 x 0.6 m flat Lambertian panel facing down
  eight      eight 1 mm emitters on a 0.2 m ring, cos^2 lobes down, fluxes 1:2:...:8
  enclosed   a 2 mm ball source, isotropic, recorded where rays leave a 2 cm sphere
  tube       1.2 m x 13 mm Lambertian tube
  downlight  0.1 m disc, directions uniform in a 20 degree cone down
  uniform    0.1 m square, directions uniform over the lower hemisphere
  batwing    0.1 m square, lower hemisphere with density ∝ sin^2 theta (per solid angle)

Usage: chart_line_clustering.py [--lumx PATH] [--rays N] [--seeds 1 2 3] [--only NAME ...] [--keep DIR]
"""
import argparse
import math
import os
import random
import re
import subprocess
import sys
import tempfile


def lambert_about(rng, n, exponent=1.0):
    """A direction with density ∝ cos^exponent about unit n."""
    ct = rng.random() ** (1.0 / (exponent + 1.0))
    st = math.sqrt(max(0.0, 1.0 - ct * ct))
    ph = 2 * math.pi * rng.random()
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    t = cross(n, a)
    t = scale(t, 1.0 / norm(t))
    b = cross(n, t)
    return tuple(ct * n[i] + st * math.cos(ph) * t[i] + st * math.sin(ph) * b[i] for i in range(3))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def scale(a, s):
    return tuple(x * s for x in a)


def unit(rng):
    while True:
        v = (rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1))
        n = norm(v)
        if n > 1e-12:
            return scale(v, 1.0 / n)


def down_uniform(rng):
    ct = rng.random()
    st = math.sqrt(1 - ct * ct)
    ph = 2 * math.pi * rng.random()
    return (st * math.cos(ph), st * math.sin(ph), -ct)


def generate(name, n, rng):
    """Yields (position, direction, flux) for geometry `name`."""
    flux = 1000.0 / n
    if name == "eight":
        weights = [k + 1 for k in range(8)]
        for i in range(n):
            k = rng.choices(range(8), weights)[0]
            a = 2 * math.pi * k / 8
            r, ph = 0.0005 * math.sqrt(rng.random()), 2 * math.pi * rng.random()
            p = (0.2 * math.cos(a) + r * math.cos(ph), 0.2 * math.sin(a) + r * math.sin(ph), 0.0)
            yield p, lambert_about(rng, (0.0, 0.0, -1.0), 2.0), flux
        return
    for _ in range(n):
        if name == "sphere":
            nrm = unit(rng)
            yield scale(nrm, 0.03), lambert_about(rng, nrm), flux
        elif name == "panel":
            yield (rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.0), lambert_about(rng, (0.0, 0.0, -1.0)), flux
        elif name == "enclosed":
            q = scale(unit(rng), 0.001 * rng.random() ** (1 / 3))
            w = unit(rng)
            b = sum(q[i] * w[i] for i in range(3))
            t = -b + math.sqrt(b * b - sum(x * x for x in q) + 0.02 ** 2)
            yield tuple(q[i] + t * w[i] for i in range(3)), w, flux
        elif name == "tube":
            ph = 2 * math.pi * rng.random()
            nrm = (0.0, math.cos(ph), math.sin(ph))
            yield (rng.uniform(-0.6, 0.6), 0.013 * nrm[1], 0.013 * nrm[2]), lambert_about(rng, nrm), flux
        elif name == "downlight":
            r, ph = 0.05 * math.sqrt(rng.random()), 2 * math.pi * rng.random()
            c20 = math.cos(math.radians(20))
            ct = 1 - rng.random() * (1 - c20)
            st, ph2 = math.sqrt(1 - ct * ct), 2 * math.pi * rng.random()
            yield (r * math.cos(ph), r * math.sin(ph), 0.0), (st * math.cos(ph2), st * math.sin(ph2), -ct), flux
        elif name in ("uniform", "batwing"):
            while True:
                w = down_uniform(rng)
                if name == "uniform" or rng.random() <= 1 - w[2] * w[2]:
                    break
            yield (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), 0.0), w, flux
        else:
            raise ValueError(name)


GEOMETRIES = ["sphere", "panel", "eight", "enclosed", "tube", "downlight", "uniform", "batwing"]
DISTANCES = ["0.5", "1", "2", "10"]


def write_rays(path, name, n, seed):
    rng = random.Random(seed)
    with open(path, "w") as f:
        f.write("# lumx-rays length=m flux=lm\n")
        for p, w, flux in generate(name, n, rng):
            f.write("%.9g %.9g %.9g %.9g %.9g %.9g %.9g\n" % (p + w + (flux,)))


def run(lumx, rays, out, extra):
    r = subprocess.run([lumx, "build", "--threads", "1", *extra, rays, out], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("lumx build failed on %s: %s" % (rays, r.stderr))
    return r.stdout


def table(text):
    """{row name: {d: value}} of the relative RMSE table, and the lines: figures."""
    lines = text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("relative RMSE"))
    header = lines[start + 1].split()
    cols = {d: header.index(d) for d in DISTANCES}
    rows = {}
    for l in lines[start + 2:]:
        if not l.strip():
            break
        parts = l.split()
        if parts[0] == "noise":
            values = parts[2:]
            rows["floor"] = {d: float(values[cols[d] - 4]) for d in DISTANCES}
        elif parts[0] == "far":
            continue
        else:
            rows["L" + parts[0]] = {d: float(parts[cols[d]]) for d in DISTANCES}
    info = " ".join(l.strip() for l in lines if l.startswith("lines:") or "clustered by" in l)
    m = re.search(r"\(ratio ([0-9.]+)\)", info)
    choice = re.search(r"clustered by ([a-z ]+);", info)
    return rows, (m.group(1) if m else "?"), (choice.group(1) if choice else "?")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lumx", default=os.path.join(os.path.dirname(__file__), "..", "build", "converters", "lumx"))
    ap.add_argument("--rays", type=int, default=200000)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--only", nargs="+", default=GEOMETRIES, choices=GEOMETRIES)
    ap.add_argument("--keep", help="write the raysets here and keep them")
    a = ap.parse_args()
    work = a.keep or tempfile.mkdtemp(prefix="lumx_chart_")
    os.makedirs(work, exist_ok=True)
    for name in a.only:
        results = []
        for seed in a.seeds:
            rays = os.path.join(work, "%s_%d.txt" % (name, seed))
            write_rays(rays, name, a.rays, seed)
            default = table(run(a.lumx, rays, os.path.join(work, "d.lumx"), []))
            classic = table(run(a.lumx, rays, os.path.join(work, "c.lumx"), ["--no-converge"]))
            results.append((default, classic))
            if not a.keep:
                os.remove(rays)
        print("== %s: ratio to shuffled %s, clustered by %s" % (
            name, " ".join(r[0][1] for r in results), " / ".join(r[0][2] for r in results)))
        print("%-6s" % "" + "".join("%18s" % ("d = " + d) for d in DISTANCES) + "   (default / --no-converge, mean of seeds)")
        for row in results[0][0][0]:
            cells = []
            for d in DISTANCES:
                dv = sum(r[0][0][row][d] for r in results) / len(results)
                cv = sum(r[1][0][row][d] for r in results) / len(results)
                cells.append("%18s" % ("%.2f" % dv if row == "floor" else "%.2f / %.2f" % (dv, cv)))
            print("%-6s" % row + "".join(cells))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
