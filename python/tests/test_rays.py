# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx.open_rays, lumx.write_tm25: streamed chunks as structured arrays, header facts against the lumx
CLI on the real TM-25 files in ../shared/data/raysets, located errors, and the memory a streamed
10 M-ray file takes."""
import json
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import lumx
from conftest import shared_dir, shared_file

RAYSETS = "raysets/JuliusMuschaweck+TM25RaySetTools"


def synthetic_rays(n, seed=1, flux=1e-4):
    """A 5 mm Lambertian disk facing down: start points on the disk, cosine-weighted directions."""
    rng = np.random.default_rng(seed)
    r = 0.005 * np.sqrt(rng.random(n))
    a = 2 * np.pi * rng.random(n)
    u1, u2 = rng.random(n), 2 * np.pi * rng.random(n)
    s = np.sqrt(u1)
    chunk = np.zeros(n, dtype=lumx.ray_dtype())
    chunk["position"] = np.stack([r * np.cos(a), r * np.sin(a), np.zeros(n)], axis=1)
    d = np.stack([s * np.cos(u2), s * np.sin(u2), -np.sqrt(1 - u1)], axis=1)
    chunk["direction"] = d / np.linalg.norm(d, axis=1, keepdims=True)
    chunk["flux"] = flux
    return chunk


def test_real_tm25_files_match_the_cli(cli):
    folder = shared_dir() / "data" / RAYSETS
    files = sorted(p for p in folder.glob("*") if p.suffix.lower() == ".tm25ray") if folder.is_dir() else []
    if not files:
        shared_file(RAYSETS)
    for path in files:
        info = cli.json("info", path)
        with lumx.open_rays(str(path), chunk_rays=10000) as f:
            assert f.info.format == info["format"] and f.info.ray_count == info["rays"]
            assert f.info.flux_unit == info["flux_unit"] and f.info.quantity == info["quantity"]
            assert f.info.header_flux == info["header_flux"]
            assert f.info.text == info["text"]
            rays, flux = 0, 0.0
            lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                chunks = list(f)
            # The reader's end-of-pass warnings (header flux against the rays' sum) are the CLI's.
            assert [str(w.message) for w in caught] == [
                f"{w['file']}:@{w['byte_offset']}: {w['severity']}: {w['field']}: {w['message']}"
                for w in info["warnings"]], path
            for chunk in chunks:
                assert chunk.dtype.names[:3] == ("position", "direction", "flux")
                assert 0 < len(chunk) <= 10000
                rays += len(chunk)
                flux += float(np.sum(chunk["flux"], dtype=np.float64))
                lo = np.minimum(lo, chunk["position"].min(axis=0))
                hi = np.maximum(hi, chunk["position"].max(axis=0))
                assert np.allclose(np.linalg.norm(chunk["direction"], axis=1), 1, atol=1e-6)
            assert rays == info["rays"]
            # NumPy sums each chunk pairwise, C++ ray by ray: both in double, ~1e-15 apart.
            assert flux == pytest.approx(info["flux_sum"], rel=1e-12)
            np.testing.assert_array_equal(lo, info["bounding_box_m"]["min"])
            np.testing.assert_array_equal(hi, info["bounding_box_m"]["max"])
            s = f.summary()
            assert s["flux_sum"] == info["flux_sum"] and s["rays"] == info["rays"]
            assert s["radius"] == info["bounding_sphere_m"]["radius"]


def test_write_read_round_trip(tmp_path):
    rays = synthetic_rays(1000)
    path = tmp_path / "disk.tm25ray"
    lumx.write_tm25(str(path), rays, text={"name": "a Lambertian disk"})
    with lumx.open_rays(str(path), chunk_rays=300) as f:
        assert f.info.ray_count == 1000 and f.info.format == "TM-25"
        # The header holds the total as a float32: within its half ulp, 2^-24 relative.
        assert f.info.header_flux == pytest.approx(float(np.sum(rays["flux"], dtype=np.float64)), rel=2**-24)
        assert f.info.text["name"] == "a Lambertian disk"
        back = np.concatenate(list(f))
        again = f.read_all(max_rays=1000)
    # TM-25 stores positions in mm: metre floats come back within 1 ulp (docs/rays.md), the rest exactly.
    np.testing.assert_array_max_ulp(back["position"], rays["position"], maxulp=1)
    np.testing.assert_array_equal(back["direction"], rays["direction"])
    np.testing.assert_array_equal(back["flux"], rays["flux"])
    np.testing.assert_array_equal(again, back)


def test_iterables_and_callables_of_chunks(tmp_path):
    chunks = [synthetic_rays(100, seed=s) for s in range(3)]
    lumx.write_tm25(str(tmp_path / "a.tm25ray"), iter(chunks))
    lumx.write_tm25(str(tmp_path / "b.tm25ray"), lambda: iter(chunks))
    mapping = {"position": chunks[0]["position"], "direction": chunks[0]["direction"], "flux": chunks[0]["flux"]}
    lumx.write_tm25(str(tmp_path / "c.tm25ray"), mapping)
    for name, n in (("a", 300), ("b", 300), ("c", 100)):
        with lumx.open_rays(str(tmp_path / f"{name}.tm25ray")) as f:
            assert f.info.ray_count == n
    # A rayset converted from an open file keeps its header.
    with lumx.open_rays(str(tmp_path / "a.tm25ray")) as f:
        lumx.write_tm25(str(tmp_path / "d.tm25ray"), f)
    with lumx.open_rays(str(tmp_path / "d.tm25ray")) as f:
        assert f.info.ray_count == 300


def test_an_exception_in_the_chunks_stops_the_writer(tmp_path):
    def broken():
        yield synthetic_rays(10)
        raise KeyError("no more rays")

    with pytest.raises(KeyError):
        lumx.write_tm25(str(tmp_path / "x.tm25ray"), broken())
    assert not (tmp_path / "x.tm25ray").exists()  # atomic: nothing left behind
    bad = synthetic_rays(10)
    bad["flux"][3] = np.nan
    with pytest.raises(lumx.Error) as e:
        lumx.write_tm25(str(tmp_path / "y.tm25ray"), bad)
    assert e.value.field and e.value.file == str(tmp_path / "y.tm25ray")


def test_bad_ray_files_are_located_errors(tmp_path):
    path = tmp_path / "ok.tm25ray"
    lumx.write_tm25(str(path), synthetic_rays(100))
    data = path.read_bytes()
    short = tmp_path / "short.tm25ray"
    short.write_bytes(data[:-10])  # the header counts more rays than the file holds
    with pytest.raises(lumx.Error) as e:
        lumx.open_rays(str(short))
    assert e.value.file == str(short) and e.value.byte_offset is not None and e.value.line is None
    findings = lumx.check(str(short))
    assert len(findings) == 1 and findings[0].severity == "error"
    assert findings[0].byte_offset == e.value.byte_offset
    assert lumx.check(str(path)) == [] or all(f.severity != "error" for f in lumx.check(str(path)))
    with pytest.raises(FileNotFoundError):
        lumx.open_rays(str(tmp_path / "absent.tm25ray"))


STREAM = textwrap.dedent("""
    import json, resource, sys
    import numpy as np
    import lumx
    def peak():  # bytes; ru_maxrss is in KiB on Linux
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    path, n = sys.argv[2], int(sys.argv[3])
    baseline = peak()
    if sys.argv[1] == "write":
        sys.path.insert(0, sys.argv[4])
        from test_rays import synthetic_rays
        per = 100000
        def chunks():
            for k in range(0, n, per):
                yield synthetic_rays(min(per, n - k), seed=k)
        lumx.write_tm25(path, chunks)
        print(json.dumps({"baseline": baseline, "peak": peak()}))
    else:
        rays, flux = 0, 0.0
        with lumx.open_rays(path) as f:
            for chunk in f:
                rays += len(chunk)
                flux += float(np.sum(chunk["flux"], dtype=np.float64))
            count = f.info.ray_count
            streamed = peak()
            # The control: the same measure sees every ray held at once.
            everything = f.read_all(n)
            held = peak()
        print(json.dumps({"baseline": baseline, "peak": streamed, "held": held, "rays": rays, "flux": flux,
                          "count": count}))
""")


def test_a_streamed_10m_ray_file_stays_within_a_memory_bound(tmp_path):
    """10 M rays are 280 MB as float32 (28 bytes a ray). Streaming reads a bounded window and hands out
    65536-ray chunks (1.8 MB), so the reading process may grow by at most 64 MiB over its size after
    `import lumx` — under a quarter of the rays' size, so holding them all would fail the test. The
    writer, fed 100 000-ray chunks, gets the same bound. As a control, read_all then holds every ray and
    the same measure must see it. LUMX_TEST_STREAM_RAYS sets the count (default
    10 M); the bound does not depend on it, so a smaller count only tests less."""
    n = int(os.environ.get("LUMX_TEST_STREAM_RAYS", "10000000"))
    path = tmp_path / "stream.tm25ray"
    here = os.path.dirname(os.path.abspath(__file__))
    bound = 64 << 20

    def run(*args):
        r = subprocess.run([sys.executable, "-c", STREAM, *map(str, args)], capture_output=True, text=True,
                           env=os.environ)
        assert r.returncode == 0, r.stderr
        return json.loads(r.stdout)

    try:
        w = run("write", path, n, here)
        size = path.stat().st_size
        s = run("read", path, n)
    finally:
        path.unlink(missing_ok=True)  # 280 MB: not left for pytest's kept temporary folders
    assert size > 28 * n
    print(f"\n{n} rays, {size / 2**20:.0f} MiB on disk; writer grew by "
          f"{(w['peak'] - w['baseline']) / 2**20:.1f} MiB, streaming reader by "
          f"{(s['peak'] - s['baseline']) / 2**20:.1f} MiB, read_all by {(s['held'] - s['baseline']) / 2**20:.1f} MiB")
    assert s["held"] - s["baseline"] >= 28 * n * 0.9  # the measure would see the rays held at once
    assert s["rays"] == n and s["count"] == n
    # Every flux is float32(1e-4): its 24 significant bits times n < 2^29 add up exactly in double.
    assert s["flux"] == n * float(np.float32(1e-4))
    assert s["peak"] - s["baseline"] < bound
    assert w["peak"] - w["baseline"] < bound
