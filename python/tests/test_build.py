# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx.build against `lumx build`: the same rays and options give the same bundle, byte for byte in
its payloads; progress reaches Python; an exception in the callback stops the build."""
import json

import numpy as np
import pytest

import lumx
from conftest import shared_file
from test_rays import synthetic_rays

RAYS = "raysets/JuliusMuschaweck+TM25RaySetTools/Cyl10k.1.tm25ray"


def test_build_equals_the_cli(cli, tmp_path):
    rays = str(shared_file(RAYS))
    theirs, ours = tmp_path / "cli.lumx", tmp_path / "py.lumx"
    cli("build", rays, theirs, "--levels", 1, 8, 64, "--threads", 2)
    calls = []
    r = lumx.build(rays, str(ours), levels=[1, 8, 64], threads=2, progress=lambda f, phase: calls.append((f, phase)))
    a = json.loads((theirs / "manifest.json").read_text())
    b = json.loads((ours / "manifest.json").read_text())
    # The levels, error tables, payload checksums and far-field attachments: everything but the text
    # of the provenance entries that name the tool are the same.
    assert a == b
    assert r.apl_counts == [1, 8, 64] and r.error_tables and r.bundle == str(ours)
    with lumx.open_rays(rays) as f:
        assert r.rays == f.info.ray_count
    bundle = lumx.Bundle(str(ours))
    assert r.map_resolutions == [m[0] for m in bundle.map_resolutions]
    far = bundle.read_attachment("far_field.ies")
    assert far == (theirs / "attachments" / "far_field.ies").read_bytes()
    fractions = [f for f, _ in calls]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0 and len(calls) > 5
    assert {"seeds", "assign", "done"} <= {p for _, p in calls}


def test_progress_exception_stops_the_build(tmp_path):
    out = tmp_path / "never.lumx"

    def stop(fraction, phase):
        if fraction > 0.1:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        lumx.build(synthetic_rays(20000), str(out), levels=[1, 8], progress=stop)
    assert not out.exists()


def test_build_from_arrays_and_chunks(tmp_path):
    rays = synthetic_rays(20000, seed=4)
    r = lumx.build(rays, str(tmp_path / "a.lumx"), levels=[1, 8], evaluate=False)
    b = lumx.Bundle(str(tmp_path / "a.lumx"))
    assert b.apl_counts == r.apl_counts == [1, 8]
    total = float(np.sum(rays["flux"], dtype=np.float64))
    assert b.level_flux(0) == pytest.approx(total, rel=1e-6)  # every ray's flux lands in every level
    # A callable is read again on each pass; the bundle is the same as from the arrays.
    chunks = [rays[:7000], rays[7000:]]
    lumx.build(lambda: iter(chunks), str(tmp_path / "b.lumx"), levels=[1, 8], evaluate=False)
    ma = json.loads((tmp_path / "a.lumx" / "manifest.json").read_text())
    mb = json.loads((tmp_path / "b.lumx" / "manifest.json").read_text())
    assert ma["levels"] == mb["levels"]
    with pytest.raises(ValueError):
        lumx.build(iter(chunks), str(tmp_path / "c.lumx"), levels=[1, 8], evaluate=False)


def test_the_gil_is_released_while_building(tmp_path):
    """A build in another thread leaves this one running Python: it counts on while the build works."""
    import threading
    import time

    rays = synthetic_rays(200000, seed=9)
    done = threading.Event()
    counts = []

    def work():
        lumx.build(rays, str(tmp_path / "t.lumx"), levels=[1, 8, 64], threads=1)
        done.set()

    t = threading.Thread(target=work)
    start = time.perf_counter()
    t.start()
    n = 0
    while not done.is_set():
        n += 1
        if n % 100000 == 0:
            counts.append(time.perf_counter() - start)
    t.join()
    seconds = time.perf_counter() - start
    # Holding the GIL, the build would stall this loop for its whole length; released, the loop ticks
    # through it (the interpreter still switches threads every 5 ms, hence no exact figure).
    assert seconds > 0.2, "the build was too quick to tell"
    assert len(counts) > 10 and max(b - a for a, b in zip([0.0] + counts, counts)) < seconds / 2


def test_what_the_build_leaves_out_is_a_warning(tmp_path):
    # Rays in W with no efficacy known: no far field can be attached, and the build says so.
    rays_path = tmp_path / "watts.tm25ray"
    lumx.write_tm25(str(rays_path), synthetic_rays(20000), quantity="radiometric")
    with pytest.warns(lumx.LumxWarning, match="efficacy") as caught:
        r = lumx.build(str(rays_path), str(tmp_path / "w.lumx"), levels=[1, 8], evaluate=False)
    assert any(w.message.severity == "note" and w.message.file == str(rays_path) for w in caught)
    assert np.isnan(r.far_field_flux_lm)
    assert lumx.Bundle(str(tmp_path / "w.lumx")).attachments == []
    r = lumx.build(str(rays_path), str(tmp_path / "v.lumx"), levels=[1, 8], evaluate=False, efficacy_lm_per_w=300)
    assert "far_field.ies" in lumx.Bundle(str(tmp_path / "v.lumx")).attachments
    # 300 lm/W times the rays' 2 W; the far field tabulates level 0's map on a 2.5 x 1 degree grid, whose
    # bilinear table integrates a smooth distribution to well within 0.1 % (measured: 5e-5).
    assert r.far_field_flux_lm == pytest.approx(300 * 20000 * float(np.float32(1e-4)), rel=1e-3)


def pinhole_rays(n, seed=2, flux=1e-3):
    """A point source at (0.01, 0, 0) behind a square hole 2 cm wide in the plane z = 0.05 m: rays start in
    the hole, every line through the source."""
    rng = np.random.default_rng(seed)
    source = np.array([0.01, 0.0, 0.0])
    hole = np.stack([rng.uniform(-0.01, 0.01, n), rng.uniform(-0.01, 0.01, n), np.full(n, 0.05)], axis=1)
    d = hole - source
    chunk = np.zeros(n, dtype=lumx.ray_dtype())
    chunk["position"] = hole
    chunk["direction"] = d / np.linalg.norm(d, axis=1, keepdims=True)
    chunk["flux"] = flux
    return chunk


def test_point_sources_can_be_kept_or_left_clustered(tmp_path):
    """point_sources=True (the default, as `lumx build`): lines through one point give one masked APL;
    False (`--no-point-sources`): the clustered levels asked for."""
    rays = pinhole_rays(20000)
    masked = lumx.build(rays, str(tmp_path / "m.lumx"), levels=[1, 8], evaluate=False)
    assert masked.point_sources == 1 and masked.apl_counts == [1]
    plain = lumx.build(rays, str(tmp_path / "p.lumx"), levels=[1, 8], evaluate=False, point_sources=False)
    assert plain.point_sources == 0 and plain.apl_counts == [1, 8]
    m = json.loads((tmp_path / "m.lumx" / "manifest.json").read_text())
    assert len(m["masks"]) == 1
    assert "masks" not in json.loads((tmp_path / "p.lumx" / "manifest.json").read_text())
