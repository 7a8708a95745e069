# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx.Bundle and lumx.Level: partial loading, irradiance equal to `lumx eval --points` to the printed
digits, intensity, maps as arrays, emission sampling, the radiance volume. Bundles are made for the test:
by `lumx build` from a real TM-25 file in ../shared/data, and by the ring-luminaire sample (analytic)."""
import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import lumx
from conftest import missing, shared_file

RAYS = "raysets/JuliusMuschaweck+TM25RaySetTools/Cyl10k.1.tm25ray"


@pytest.fixture(scope="module")
def built(cli, tmp_path_factory):
    """A bundle from the real Cyl10k rays, levels 1, 8 and 64, built by the CLI."""
    out = tmp_path_factory.mktemp("bundle") / "cyl10k.lumx"
    cli("build", shared_file(RAYS), out, "--levels", 1, 8, 64, "--threads", 2)
    return out


@pytest.fixture(scope="module")
def ring(tmp_path_factory):
    """The ring-luminaire sample's bundle: 64 analytic cos^3 LEDs, levels 1/8/64, a radiance volume."""
    sample = os.environ.get("LUMX_TEST_RING_SAMPLE", "")
    if not sample or not Path(sample).exists():
        missing("the ring-luminaire sample (build target lumx_sample_ring_luminaire)")
    out = tmp_path_factory.mktemp("ring") / "ring.lumx"
    subprocess.run([sample, str(out)], check=True, capture_output=True)
    return out


def points_around(bundle, n, seed):
    """Points at relative distances 0.5 .. 10 around the bundle, normals facing roughly back at it."""
    rng = np.random.default_rng(seed)
    (centre, radius) = bundle.bounds
    d = rng.uniform(0.5, 10, n) * 2 * radius
    w = rng.normal(size=(n, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    x = np.asarray(centre) + d[:, None] * w
    nrm = -w + 0.3 * rng.normal(size=(n, 3))
    return x, nrm


def write_points(path, x, n):
    with open(path, "w") as f:
        for p, q in zip(x, n):
            f.write(" ".join(repr(float(v)) for v in (*p, *q)) + "\n")


def test_opening_reads_the_manifest_only(built):
    b = lumx.Bundle(str(built))
    assert b.bytes_read == (built / "manifest.json").stat().st_size
    manifest = json.loads((built / "manifest.json").read_text())
    assert b.apl_counts == [1, 8, 64] == [l["apl_count"] for l in manifest["levels"]]
    assert b.quantity == "photometric" and b.irradiance_unit == "lx" and b.channels == "luminance"
    assert "far_field.ies" in b.attachments
    positions = b.level_positions(2)
    assert positions.shape == (64, 3)
    assert b.bytes_read == (built / "manifest.json").stat().st_size  # still no payload read


def test_load_level_reads_one_payload_at_the_asked_resolution(ring):
    b = lumx.Bundle(str(ring))
    manifest = json.loads((ring / "manifest.json").read_text())
    before = b.bytes_read
    stored = b.map_resolutions[2]
    assert len(stored) > 2 and stored == sorted(stored, reverse=True)
    level = b.load_level(2, max_resolution=stored[1] + 1)  # the largest stored one not above it
    assert level.map_resolution == stored[1] and level.apl_count == 64
    payload = next(m for m in manifest["levels"][2]["maps"] if m["resolution"] == stored[1])
    assert b.bytes_read - before == payload["bytes"] == (ring / payload["file"]).stat().st_size
    coarse = b.load_level(2, max_resolution=1)  # below every stored one: the coarsest
    assert coarse.map_resolution == stored[-1]
    assert level.map_resolution == stored[1] and level.map(0).shape[0] == stored[1]  # the first Level kept its maps


def test_irradiance_equals_lumx_eval_points(built, cli, tmp_path):
    b = lumx.Bundle(str(built))
    x, n = points_around(b, 300, seed=7)
    pts = tmp_path / "points.txt"
    write_points(pts, x, n)
    for k in range(b.level_count):
        theirs = cli("eval", built, "--points", pts, "--level", k).stdout.split()
        ours = lumx.Bundle(str(built)).irradiance(x, n, level=k)  # a fresh bundle: full resolution, as the CLI
        assert ours.shape == (300,)
        assert [f"{v:.9g}" for v in ours] == theirs, f"level {k}"
    theirs = cli("eval", built, "--points", pts, "--lod").stdout.split()
    ours = lumx.Bundle(str(built)).irradiance(x, n, lod=True)
    assert [f"{v:.9g}" for v in ours] == theirs
    theirs = cli("eval", built, "--points", pts, "--lod", "--seed", 5).stdout.split()
    ours = lumx.Bundle(str(built)).irradiance(x, n, lod=True, seed=5)
    assert [f"{v:.9g}" for v in ours] == theirs


def test_irradiance_level_choice(built):
    b = lumx.Bundle(str(built))
    x, n = points_around(b, 50, seed=3)
    d, rmse = b.level(0).error_table
    assert len(d) > 0 and len(d) == len(rmse)  # lumx build stored held-out error tables
    np.testing.assert_array_equal(b.irradiance(x, n, error_target=1e9), b.irradiance(x, n, level=0))
    np.testing.assert_array_equal(b.irradiance(x, n, error_target=-1), b.irradiance(x, n, level=-1))
    single = b.irradiance(x[0], n[0], level=1)
    assert isinstance(single, float) and single == b.irradiance(x[:1], n[:1], level=1)[0]
    u = np.zeros(50)  # u = 0 always takes the upper of the two bracketing levels
    assert np.all(b.irradiance(x, n, lod=True, u=u) > 0)
    with pytest.raises(ValueError):
        b.irradiance(x, n, level=0, lod=True)
    with pytest.raises(IndexError):
        b.irradiance(x, n, level=7)


def test_maps_are_read_only_views_holding_the_flux(built):
    b = lumx.Bundle(str(built))
    level = b.load_level(1)
    R = level.map_resolution
    texel_sr = 4 * math.pi / (2 * R * R)
    for i in range(level.apl_count):
        m = level.map(i)
        assert m.shape == (R, 2 * R, 1) and m.dtype == np.float32 and not m.flags.writeable
        assert np.shares_memory(m, level.map(i))
        # Half-float payloads round each texel by at most 2^-11 relative; the flux was summed before that.
        assert float(m.sum(dtype=np.float64)) * texel_sr == pytest.approx(level.flux[i, 0], rel=5e-4)
    all_maps = level.maps()
    assert all_maps.shape == (level.apl_count, R, 2 * R, 1)
    np.testing.assert_array_equal(all_maps[3], level.map(3))


def test_intensity_at_texel_centres_integrates_to_the_maps(built):
    b = lumx.Bundle(str(built))
    level = b.load_level(2)
    R = level.map_resolution
    xs, ys = np.meshgrid((np.arange(2 * R) + 0.5) / (2 * R), (np.arange(R) + 0.5) / R)
    m = lumx.uv_to_direction(np.stack([xs, ys], axis=-1).reshape(-1, 2))  # in the maps' frame
    frame = level.map_frame
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-6)
    w = m @ frame  # photometric directions: map_frame.T @ m per row
    # A bilinear lookup at a texel centre is that texel: the sum over centres is the maps' integral.
    total = float(np.sum(level.intensity(w))) * 4 * math.pi / (2 * R * R)
    maps = float(level.maps().sum(dtype=np.float64)) * 4 * math.pi / (2 * R * R)
    assert total == pytest.approx(maps, rel=1e-5)
    np.testing.assert_allclose(b.intensity(w[:10], level=2), level.intensity(w[:10]), rtol=1e-12)
    np.testing.assert_allclose(lumx.direction_to_uv(m[:5]), np.stack([xs, ys], axis=-1).reshape(-1, 2)[:5],
                               atol=1e-6)


def test_emission_sampling(built):
    b = lumx.Bundle(str(built))
    level = b.load_level(2)
    rng = np.random.default_rng(11)
    u = rng.random((200000, 3))
    s = level.sample_emission(u)
    np.testing.assert_array_equal(b.sample_emission(u[:100]), s[:100])
    np.testing.assert_array_equal(b.pdf(s["apl"][:100], s["direction"][:100]),
                                  level.pdf(s["apl"][:100], s["direction"][:100]))
    assert np.all(s["apl"] >= 0)
    # Each sample's flux is I / pdf: an unbiased estimate of the level's flux. Five standard errors.
    f = s["flux"][:, 0].astype(np.float64)
    se = f.std() / math.sqrt(len(f))
    assert abs(f.mean() - level.flux[:, 0].sum()) < 5 * se
    np.testing.assert_allclose(level.pdf(s["apl"], s["direction"]), s["pdf_apl"] * s["pdf_direction"], rtol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(s["position"] - level.positions[s["apl"]], axis=1), 0)
    apl, prob = level.choose_light(np.array([[0.0, 0.0, -1.0]] * 4), np.array([[0.0, 0.0, 1.0]] * 4),
                                   np.array([0.1, 0.4, 0.7, 0.95]))
    assert np.all(apl >= 0) and np.all((prob > 0) & (prob <= 1))


def test_ring_irradiance_against_the_analytic_leds(ring):
    """The ring sample's 64-APL level holds each LED's cos^3 lobe on a 128 map: its irradiance below the
    ring must be the exact sum of the lobes, within the bilinear error on 1-degree texels (< 1e-3)."""
    b = lumx.Bundle(str(ring))
    phi = 2 * np.pi * (np.arange(64) + 0.5) / 64
    tilt = np.radians(20)
    pos = np.stack([0.25 * np.cos(phi), 0.25 * np.sin(phi), 0 * phi], axis=1).astype(np.float32)
    axis = np.stack([np.sin(tilt) * np.cos(phi), np.sin(tilt) * np.sin(phi), -np.cos(tilt) + 0 * phi], axis=1)
    peak = 1000 / 64 / (2 * np.pi / 4)
    x = np.array([[0, 0, -1.0], [0.3, 0.1, -2.0], [-0.5, 0.4, -1.5], [1.0, -1.0, -3.0]])
    n = np.array([[0, 0, 1.0]] * len(x))
    exact = []
    for p in x:
        d = p - pos
        r = np.linalg.norm(d, axis=1)
        w = d / r[:, None]
        lobe = peak * np.clip(np.sum(w * axis, axis=1), 0, None) ** 3
        exact.append(np.sum(lobe * np.clip(-(w @ n[0]), 0, None) / r**2))
    np.testing.assert_allclose(b.irradiance(x, n, level=2), exact, rtol=1e-3)


def test_radiance_volume(ring, built):
    b = lumx.Bundle(str(ring))
    assert b.has_volume
    v = b.load_volume()
    nx, ny, nz = v.counts
    c = v.coefficients
    assert c.shape == (nz, ny, nx, v.channels, v.bands**2) and not c.flags.writeable
    np.testing.assert_allclose(np.array(v.hi) - np.array(v.lo), np.array(v.counts) * v.voxel_size, rtol=1e-12)
    # Inside the ring's box, below an LED, light travels downwards, not upwards.
    p = np.array([[0.25, 0.0, -0.005]] * 2)
    down, up = v.radiance(p, np.array([[0, 0, -1.0], [0, 0, 1.0]]))
    assert np.all(np.isfinite(v.radiance(p, p + 1)))
    assert down[0] > 0 and down[0] > up[0]
    with pytest.raises(ValueError):
        lumx.Bundle(str(built)).load_volume()


def test_bad_bundles_raise_located_errors(built, tmp_path):
    with pytest.raises(FileNotFoundError):
        lumx.Bundle(str(tmp_path / "absent.lumx"))
    broken = tmp_path / "broken.lumx"
    broken.mkdir()
    (broken / "manifest.json").write_text('{"format": "lumx-bundle", "format_version": 1, "levels": 3}')
    with pytest.raises(lumx.Error) as e:
        lumx.Bundle(str(broken))
    assert e.value.file and e.value.field
    findings = lumx.check(str(broken))
    assert findings and findings[0].severity == "error"
    assert lumx.check(str(built)) == []
