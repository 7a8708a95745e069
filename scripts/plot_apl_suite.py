#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Error against distance for the analytic suite (docs/apl_sets.md, docs/images/apl_suite_error.png).

The figures come from the test that grades what `lumx build` ships against the exact irradiance
(tests/test_apl_honest_error.cpp, ShippedSetSuite): with LUMX_FIGURES_DIR set it writes one CSV per
emitter, which this script draws, one panel per emitter, relative RMSE (%, eq. 5.1, single points at the
patch centres) against the relative distance d, log-log.

Usage:
  mkdir -p out/figures
  LUMX_FIGURES_DIR=out/figures build/tests/lumx_tests --gtest_filter='*ShippedSet*'
  /usr/bin/python3 scripts/plot_apl_suite.py out/figures docs/images/apl_suite_error.png

Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "finest level, fitted and smoothed (shipped)": dict(color="tab:blue", marker="o", linewidth=2.0),
    "finest level, the rule's R (before the fit)": dict(color="tab:blue", marker="o", linestyle="--", alpha=0.6),
    "far field, one point": dict(color="tab:gray", marker="s", linestyle=":"),
    "IES attachment from level 0's fitted maps": dict(color="tab:orange", marker="^"),
    "IES from the rays binned on its grid (before)": dict(color="tab:orange", marker="^", linestyle="--", alpha=0.6),
}


def read(folder):
    panels = {}
    for path in sorted(glob.glob(os.path.join(folder, "apl_suite_*.csv"))):
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                series = panels.setdefault(row["emitter"], {}).setdefault(row["series"], ([], []))
                series[0].append(float(row["d"]))
                series[1].append(100.0 * float(row["relative_rmse"]))
    return panels


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    panels = read(argv[1])
    if not panels:
        sys.stderr.write(f"{argv[1]}: no apl_suite_*.csv (run the test with LUMX_FIGURES_DIR set)\n")
        return 1
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 4.2), sharey=True)
    if len(panels) == 1:
        axes = [axes]
    for ax, (emitter, series) in zip(axes, panels.items()):
        for name, (d, e) in series.items():
            ax.plot(d, e, label=name, **STYLE.get(name, {}))
        ax.axhline(2.0, color="tab:green", linewidth=0.8)  # the 2 % target for the Lambertian emitters and spots
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(0.5, 1000.0)
        ax.set_title(emitter, fontsize=9)
        ax.set_xlabel("relative distance d")
        ax.grid(True, which="both", linewidth=0.3)
    axes[0].set_ylabel("relative RMSE at single points, % (exact reference)")
    axes[0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)
    print(f"wrote {argv[2]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
