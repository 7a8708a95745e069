# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""lumx.read_photometry, lumx.Photometry, lumx.check and the errors and warnings they raise, against the
lumx CLI on the real files in ../shared/data/photometry and lumx's own bad and edge-case files.

The CLI and the module run the same C++ and the CLI's JSON prints doubles so that they read back
exactly, so the figures agree to rounding; 1e-9 relative is far above that and far below any
difference a wrong reading, a wrong symmetry or a wrong unit would make.
"""
import errno
import json
import math
import warnings

import numpy as np
import pytest

import lumx
from conftest import SOURCE_DIR, missing, shared_photometry_files

REL = 1e-9
BAD_DIR = SOURCE_DIR / "tests" / "data" / "bad"
DOWNLIGHT = SOURCE_DIR / "samples" / "downlight.ies"


def close(a, b, rel=REL):
    return a == b or abs(a - b) <= rel * max(abs(a), abs(b))


def real_files():
    files = shared_photometry_files()
    if not files:
        missing("../shared/data/photometry (real-world data is read in place there)")
    return files


def read_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lumx.LumxWarning)
        return lumx.read_photometry(str(path))


def finding_dict(f):
    """A finding as `lumx check --json` / `lumx info --json` print one."""
    d = {"severity": f.severity, "field": f.field, "message": f.message}
    if f.line is not None:
        d["line"] = f.line
    if f.byte_offset is not None:
        d["byte_offset"] = f.byte_offset
    if f.file:
        d["file"] = f.file
    return d


def test_real_files_match_the_cli(cli):
    compared = 0
    for path in real_files():
        r = cli("info", path, "--json", check=False)
        if r.returncode != 0:  # a file the reader rejects: the module must reject it alike
            with pytest.raises(lumx.Error) as e:
                read_quietly(path)
            assert str(e.value) in r.stderr, path
            continue
        info = json.loads(r.stdout)
        p = read_quietly(path)
        s = p.summary()
        assert close(p.flux_lm, info["flux_lm"]), path
        assert close(s.flux_lm, info["flux_lm"]), path
        assert close(s.max_cd, info["max_cd"]), path
        assert float(np.max(p.candela)) == pytest.approx(info["max_cd"], rel=REL), path
        for plane in ("c0_c180", "c90_c270"):
            ours, theirs = getattr(s, plane), info[plane]
            for key in ("beam_deg", "field_deg", "peak_cd", "peak_angle_deg"):
                assert close(getattr(ours, key), theirs[key]), (path, plane, key)
        assert close(s.downward_fraction, info["downward_flux_fraction"]), path
        if info["light_output_ratio"] is None:
            assert s.light_output_ratio is None
        else:
            assert close(s.light_output_ratio, info["light_output_ratio"]), path
        compared += 1
    assert compared > 0


def test_ugr_tables_match_the_cli(cli):
    """The UGR table of every shared file that has one equals `lumx info --json`'s, cell for cell."""
    compared = 0
    for path in real_files():
        r = cli("info", path, "--json", check=False)
        if r.returncode != 0:
            continue
        theirs = json.loads(r.stdout).get("metrics", {}).get("ugr")
        p = read_quietly(path)
        if theirs is None:  # no luminous area: the module raises the located error the CLI noted
            with pytest.raises(lumx.Error):
                p.ugr_table()
            continue
        t = p.ugr_table()
        assert t["crosswise"].shape == (19, 5) and t["endwise"].shape == (19, 5)
        for view in ("crosswise", "endwise"):
            expected = np.array(theirs[view], dtype=float)
            assert np.allclose(t[view], expected, rtol=1e-12, atol=0, equal_nan=True), (path, view)
        assert np.array_equal(t["rooms_xy_h"], np.array(theirs["rooms_xy_h"], dtype=float))
        compared += 1
    if compared == 0:
        missing("no shared photometry file with a UGR table")


def test_intensity_at_the_stored_angles_is_the_stored_candela():
    """At the interior nodes of a Type C table the bilinear interpolant is the stored value; the
    directions are computed in NumPy, so this checks the vectorised query and the frame convention."""
    checked = 0
    for path in [DOWNLIGHT, *shared_photometry_files()]:
        try:
            p = read_quietly(path)
        except lumx.Error:
            continue
        if p.type != "C":
            continue
        c, g = np.meshgrid(p.horizontal_deg, p.vertical_deg, indexing="ij")
        # The poles and, in tables storing both C0 and C360, the seam are averaged (intensity_table.h).
        seam = p.horizontal_deg[0] == 0 and p.horizontal_deg[-1] == 360
        inner = (g > 0) & (g < 180) & ~(seam & ((c == 0) | (c == 360)))
        if not inner.any():
            continue
        cr, gr = np.radians(c[inner]), np.radians(g[inner])
        d = np.stack([np.sin(gr) * np.cos(cr), np.sin(gr) * np.sin(cr), -np.cos(gr)], axis=1)
        got = p.intensity(d)
        want = p.candela[inner]
        # Angles through sin/cos and back carry ~1e-15 rad of rounding: bilinear weights off by that
        # times the slope; 1e-9 of the peak bounds it for any real table.
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * max(1.0, float(want.max())), err_msg=str(path))
        checked += 1
    assert checked > 0


def test_intensity_shapes_and_flux_integral():
    p = lumx.read_photometry(str(DOWNLIGHT))
    assert isinstance(p.intensity([0, 0, -1]), float)
    assert p.intensity(np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError):
        p.intensity(np.zeros((4, 2)))
    # Midpoint rule on a 0.25 x 0.25 degree (C, gamma) grid against the exact flux of the same
    # interpolant; the rule's error on a piecewise-bilinear table with 1-degree-ish steps is ~1e-5.
    n_c, n_g = 1440, 720
    c = np.radians((np.arange(n_c) + 0.5) * 360 / n_c)
    g = np.radians((np.arange(n_g) + 0.5) * 180 / n_g)
    cc, gg = np.meshgrid(c, g, indexing="ij")
    d = np.stack([np.sin(gg) * np.cos(cc), np.sin(gg) * np.sin(cc), -np.cos(gg)], axis=-1).reshape(-1, 3)
    i = p.intensity(d).reshape(n_c, n_g)
    flux = float(np.sum(i * np.sin(gg)) * (2 * math.pi / n_c) * (math.pi / n_g))
    assert flux == pytest.approx(p.flux_lm, rel=1e-4)
    # intensity_at takes the photometric angles directly.
    np.testing.assert_allclose(p.intensity_at(np.degrees(cc), np.degrees(gg)).reshape(-1), i.reshape(-1),
                               rtol=1e-12, atol=1e-12)


def test_table_arrays_are_views_of_the_photometry():
    p = lumx.read_photometry(str(DOWNLIGHT))
    cd = p.candela
    assert cd.shape == (len(p.horizontal_deg), len(p.vertical_deg))
    assert np.shares_memory(cd, p.candela)  # the same memory each time: no copy
    flux = p.flux_lm
    cd *= 2.0  # the view is live: queries see the edit
    assert p.flux_lm == pytest.approx(2 * flux, rel=1e-12)
    del p
    assert np.all(np.isfinite(cd))  # the view keeps the photometry alive


def test_polar_curve(cli):
    p = lumx.read_photometry(str(DOWNLIGHT))
    theta, cd = p.polar_curve("C0-C180", step_deg=1.0)
    assert theta[0] == -180 and theta[-1] == 180 and len(theta) == 361
    i0 = p.intensity(np.stack([np.sin(np.radians(theta)), 0 * theta, -np.cos(np.radians(theta))], axis=1))
    np.testing.assert_allclose(cd, i0, rtol=1e-12)
    assert cd.max() == pytest.approx(p.summary().c0_c180.peak_cd, rel=1e-3)


def test_write_round_trip(tmp_path):
    p = lumx.read_photometry(str(DOWNLIGHT))
    for name in ("copy.ies", "copy.ldt"):
        p.write(str(tmp_path / name), digits=9)
        q = lumx.read_photometry(str(tmp_path / name))
        # 9 significant digits written: each value within 5e-9 relative, the flux with it.
        assert q.flux_lm == pytest.approx(p.flux_lm, rel=1e-8)
    with pytest.raises(lumx.Error) as e:
        p.write(str(tmp_path / "copy.txt"))
    assert e.value.field == "output format"


def test_bad_files_give_the_cli_findings(cli):
    files = sorted(f for f in BAD_DIR.iterdir() if f.suffix in (".ies", ".ldt"))
    assert files
    for path in files:
        theirs = cli.json("check", path)[0]["findings"]
        ours = lumx.check(str(path))
        assert [finding_dict(f) for f in ours] == theirs, path


def test_errors_carry_file_line_and_field(cli):
    located = 0
    for path in sorted(BAD_DIR.iterdir()):
        if path.suffix not in (".ies", ".ldt"):
            continue
        r = cli("info", path, "--json", check=False)
        if r.returncode == 0:
            continue
        with pytest.raises(lumx.Error) as e:
            read_quietly(path)
        err = e.value
        assert isinstance(err, ValueError)
        assert err.file == str(path)
        # The CLI prints the same diagnostic, file:line: severity: field: message.
        assert str(err) in r.stderr
        assert err.severity == "error" and err.message and err.finding.message == err.message
        if err.line is not None:
            assert str(err).startswith(f"{path}:{err.line}: error: ")
            located += 1
    assert located > 0


def test_missing_file_is_an_oserror(tmp_path):
    path = tmp_path / "absent.ies"
    with pytest.raises(FileNotFoundError) as e:
        lumx.read_photometry(str(path))
    assert e.value.errno == errno.ENOENT
    assert e.value.filename == str(path)
    assert e.value.field and not isinstance(e.value, ValueError)


def test_reader_warnings_are_python_warnings(cli):
    warned = 0
    for path in sorted(BAD_DIR.iterdir()):
        if path.suffix not in (".ies", ".ldt"):
            continue
        r = cli("info", path, "--json", check=False)
        if r.returncode != 0:
            continue
        theirs = json.loads(r.stdout)["warnings"]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            lumx.read_photometry(str(path))
        ours = [w.message for w in caught if issubclass(w.category, lumx.LumxWarning)]
        assert [finding_dict(w.finding) for w in ours] == theirs, path
        for w in ours:
            assert w.file == str(path) and w.severity in ("warning", "note")
        warned += bool(ours)
    assert warned > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", lumx.LumxWarning)
        noisy = next(p for p in sorted(BAD_DIR.iterdir()) if p.suffix == ".ies" and
                     cli("info", p, "--json", check=False).returncode == 0 and
                     json.loads(cli("info", p, "--json").stdout)["warnings"])
        with pytest.raises(lumx.LumxWarning):
            lumx.read_photometry(str(noisy))


def test_check_refuses_luminaires_it_cannot_read(tmp_path):
    # glTF luminaires need the bake component, which the module does not include: a clear refusal,
    # not a photometry parse error about a file that may well be valid.
    (tmp_path / "lamp.glb").write_bytes(b"glTF")
    with pytest.raises(ValueError, match="bake component"):
        lumx.check(str(tmp_path / "lamp.glb"))
