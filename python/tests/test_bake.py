# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx.bake against `lumx bake`: the same luminaire and options give the same bundle (levels, volume, far
field, luminaire file); the passes and the stopping rule are reported; an exception in the progress
callback stops the bake and leaves the output untouched."""
import json
import math

import pytest

import lumx
from conftest import SOURCE_DIR

# One emissive triangle (0.005 m², 1000 cd/m², one-sided), a file of the project's own.
TRIANGLE = SOURCE_DIR / "tests" / "data" / "fuzz" / "gltf" / "triangle.glb"


def payloads(manifest):
    """What the bundle stores, without the provenance (which holds timings)."""
    m = dict(manifest)
    m.pop("provenance", None)
    return m


def test_bake_equals_the_cli(cli, tmp_path):
    theirs, ours = tmp_path / "cli.lumx", tmp_path / "py.lumx"
    cli("bake", TRIANGLE, theirs, "--particles", 30000, "--levels", 1, 8, "--target-error", 0, "--threads", 2,
        "--volume-voxels", 512)
    calls = []
    r = lumx.bake(str(TRIANGLE), str(ours), particles=30000, levels=[1, 8], target_error=0, threads=1,
                  volume_voxels=512, progress=lambda f, phase: calls.append((f, phase)))
    a = json.loads((theirs / "manifest.json").read_text())
    b = json.loads((ours / "manifest.json").read_text())
    assert payloads(a) == payloads(b)  # the same for any thread count
    assert r.particles == 30000 and r.exits == 30000  # every particle leaves a bare triangle
    flux = math.pi * 1000.0 * 0.005  # π L A
    assert r.emitted_lm == pytest.approx(flux, rel=1e-6)
    assert r.exited_lm == pytest.approx(flux, rel=1e-6)
    assert r.stopped_by == "particle budget" and len(r.passes) == 1 and not r.target_met
    assert r.apl_counts == [1, 8] and r.error_tables
    assert len(r.luminaire_sha256) == 64
    bundle = lumx.Bundle(str(ours))
    assert bundle.read_attachment("luminaire.glb") == TRIANGLE.read_bytes()
    assert len(calls) > 3 and {"tracing"} <= {p for _, p in calls}


def test_bake_stops_at_the_target(tmp_path):
    r = lumx.bake(str(TRIANGLE), str(tmp_path / "t.lumx"), particles=4000000, levels=[1, 8], target_error=0.5,
                  target_distance=2.0, volume_voxels=0)
    assert r.target_met and r.stopped_by == "target error"
    assert len(r.passes) == 1 and r.particles == 2 ** 18 < 4000000
    p = r.passes[0]
    assert p.error <= 0.5 and p.error >= p.error_estimate and len(p.level_error) == 2


def test_progress_exception_stops_the_bake(tmp_path):
    out = tmp_path / "never.lumx"

    def stop(fraction, phase):
        if phase == "tracing" and fraction > 0.2:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        lumx.bake(str(TRIANGLE), str(out), particles=200000, levels=[1, 8], target_error=0, progress=stop)
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if ".tmp-" in p.name]  # no scratch file left behind


def test_a_broken_luminaire_is_a_located_error(tmp_path):
    bad = tmp_path / "bad.glb"
    bad.write_bytes(TRIANGLE.read_bytes()[:40])
    with pytest.raises(lumx.Error) as e:
        lumx.bake(str(bad), str(tmp_path / "b.lumx"), particles=1000)
    assert e.value.file.endswith("bad.glb")
