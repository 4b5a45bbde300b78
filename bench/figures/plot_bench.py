#!/usr/bin/env python3
"""Plots from bench/results/peers.json:

- docs/images/convergence.png: error against vertex count on icospheres
  (great-circle distance) and on the 3x stretched obtuse lattice (Euclidean
  distance), every method, log-log, with the fitted order in the legend
  (err ~ n^s, i.e. h^p with p = -2 s, h the edge length).
- docs/images/scaling.png: median time per source against vertex count on
  icospheres and sine surfaces, with an n log n reference line.

    python bench/figures/plot_bench.py [peers.json]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib as bl  # noqa: E402

STYLE = {
    "meshfmm": dict(color="C3", marker="o", lw=2.2, label="meshfmm"),
    "meshfmm_nounfold": dict(color="C1", marker="o", lw=1.2, ls="--", mfc="none",
                             label="meshfmm, no unfolding"),
    "gc_fmm": dict(color="C0", marker="s", lw=1.4, label="geometry-central FMM"),
    "gc_heat": dict(color="C2", marker="^", lw=1.4, label="geometry-central heat"),
    "igl_heat": dict(color="C4", marker="v", lw=1.4, label="libigl heat"),
    "gdist": dict(color="0.3", marker="D", lw=1.2, label="gdist (exact MMP)"),
    "igl_exact": dict(color="C5", marker="x", lw=1.2, ls=":", label="igl.exact_geodesic (exact MMP)"),
}
ORDER = list(STYLE)


def family(doc, fam):
    return sorted([c for c in doc["cases"] if c["family"] == fam], key=lambda c: c["n_vertices"])


def fit(n, y):
    n, y = np.asarray(n, float), np.asarray(y, float)
    ok = np.isfinite(y) & (y > 0)
    if ok.sum() < 2:
        return None
    s, _ = np.polyfit(np.log(n[ok]), np.log(y[ok]), 1)
    return s


def convergence(doc, out):
    fig, axs = plt.subplots(2, 2, figsize=(12, 9.5), sharex="col")
    for col, (fam, title) in enumerate([("sphere", "icospheres, great-circle distance"),
                                        ("lattice", "3x stretched lattice (120° corners), "
                                                    "Euclidean distance")]):
        cases = family(doc, fam)
        for row, (key, ylab) in enumerate([("mre_pct", "mean relative error (%)"),
                                           ("max_pct", "max error (% of bbox diagonal)")]):
            ax = axs[row, col]
            for m in ORDER:
                pts = [(c["n_vertices"], c["methods"].get(m, {}).get(key)) for c in cases]
                pts = [(n, y) for n, y in pts if y is not None and np.isfinite(y) and y > 1e-9]
                if len(pts) < 2:
                    continue
                n, y = zip(*pts)
                s = fit(n, y)
                st = dict(STYLE[m])
                lab = st.pop("label") + f"  (h^{-2 * s:.2f})"
                ax.loglog(n, y, label=lab, ms=5, **st)
            ax.set_title(f"{title}: {ylab.split(' (')[0]}", fontsize=10)
            ax.set_ylabel(ylab)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8, loc="lower left")
            if row == 1:
                ax.set_xlabel("vertices n  (fitted order p: error ~ h^p ~ n^(-p/2))")
    note = ("exact methods are not drawn on the plane: they are exact there (error < 1e-9 %)"
            if any("gdist" in c["methods"] for c in family(doc, "lattice")) else "")
    m = doc["machine"]
    fig.suptitle("Convergence: error against vertex count (3 fixed sources per mesh)\n" + note,
                 fontsize=11)
    fig.text(0.99, 0.005, f"{m['cpu_model']}, {m['date_utc'][:10]}", ha="right", fontsize=7,
             color="0.4")
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)


def scaling(doc, out):
    fig, axs = plt.subplots(1, 2, figsize=(13, 5.8))
    for ax, (fam, title) in zip(axs, [("sphere", "icospheres"),
                                      ("sine", "sine surfaces z = 0.45 sin 2πx sin 2πy")]):
        cases = family(doc, fam)
        for m in ORDER:
            if m == "meshfmm_nounfold":
                continue
            pts = [(c["n_vertices"], c["methods"].get(m, {}).get("time_s")) for c in cases]
            pts = [(n, t) for n, t in pts if t]
            if len(pts) < 2:
                continue
            n, t = zip(*pts)
            st = dict(STYLE[m])
            s = fit(n, t)
            lab = st.pop("label") + (" solve" if "heat" in m else "") + f"  (~n^{s:.2f})"
            ax.loglog(n, np.array(t) * 1e3, label=lab, ms=5, **st)
        # precomputes of the heat methods, dotted
        for m in ("gc_heat", "igl_heat"):
            pts = [(c["n_vertices"], c["methods"].get(m, {}).get("setup_s")) for c in cases]
            pts = [(n, t) for n, t in pts if t]
            if len(pts) >= 2:
                n, t = zip(*pts)
                ax.loglog(n, np.array(t) * 1e3, color=STYLE[m]["color"], ls=":", lw=1,
                          marker=".", label=STYLE[m]["label"] + " precompute (once)")
        ref = [(c["n_vertices"], c["methods"].get("meshfmm", {}).get("time_s")) for c in cases]
        ref = [(n, t) for n, t in ref if t]
        if ref:
            n0, t0 = ref[-1]
            nn = np.geomspace(min(n for n, _ in ref), n0, 50)
            ax.loglog(nn, t0 * 1e3 * nn * np.log(nn) / (n0 * np.log(n0)), color="k", lw=0.8,
                      ls="--", label="n log n (through meshfmm's largest)")
        ax.set_title(f"{title}: median time per source", fontsize=10)
        ax.set_xlabel("vertices n")
        ax.set_ylabel("ms per source")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7.5, loc="upper left")
    m = doc["machine"]
    fig.suptitle(f"Scaling, one thread each, on {m['cpu_model']} ({m['logical_cpus']} logical CPUs), "
                 f"{m['date_utc'][:10]}", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)


def main():
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else bl.RESULTS / "peers.json"
    doc = json.loads(src.read_text())
    bl.IMAGES.mkdir(parents=True, exist_ok=True)
    convergence(doc, bl.IMAGES / "convergence.png")
    scaling(doc, bl.IMAGES / "scaling.png")
    print(bl.IMAGES / "convergence.png")
    print(bl.IMAGES / "scaling.png")


if __name__ == "__main__":
    main()
