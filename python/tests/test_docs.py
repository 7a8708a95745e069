# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""The example script of docs/python.md runs: on a real photometry file and a bundle built from the
synthetic disk rays, writing both plots."""
import re
import subprocess
import sys

import pytest

import lumx
from conftest import SOURCE_DIR, shared_photometry_files
from test_rays import synthetic_rays


def example_script():
    text = (SOURCE_DIR / "docs" / "python.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    scripts = [b for b in blocks if b.startswith("# example:")]
    assert len(scripts) == 1
    return scripts[0]


def test_the_example_script_runs(tmp_path):
    pytest.importorskip("matplotlib")
    files = [p for p in shared_photometry_files() if p.suffix.lower() == ".ies"]
    photometry = files[0] if files else SOURCE_DIR / "samples" / "downlight.ies"
    bundle = tmp_path / "disk.lumx"
    lumx.build(synthetic_rays(50000), str(bundle), levels=[1, 8, 64], evaluate=False)
    script = tmp_path / "example.py"
    script.write_text(example_script())
    r = subprocess.run([sys.executable, str(script), str(photometry), str(bundle), str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "polar.png").stat().st_size > 1000
    assert (tmp_path / "levels.png").stat().st_size > 1000
    assert r.stdout.startswith("floor mean:")
