#!/usr/bin/env python3
"""Compare bench_solve builds: run them in alternating order over rounds (so
that load from other work falls on each alike) and print, per unfolding
setting, the median of the rounds' medians and the least minimum, each also
relative to the first build, with the Dijkstra ceiling and the ratio.

    python bench/micro/ab_solve.py --rounds 10 MESH OLD/bench_solve NEW/bench_solve
    python bench/micro/ab_solve.py --rounds 10 --exact-start 7 MESH OLD NEW ...

A build is named by the directory above its build/ (or by its path).
"""
import argparse
import os
import re
import statistics
import subprocess

LINE = re.compile(r"unfolding=(\d).*?solve median=\s*([\d.]+) ms.*?Dijkstra ceiling\s+([\d.]+) ms"
                  r".*?\(min\s+([\d.]+) /\s+([\d.]+) ms")


def name(path):
    parts = os.path.abspath(path).split(os.sep)
    return parts[parts.index("build") - 1] if "build" in parts else path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=10)
    ap.add_argument("--repeats", default="7")
    ap.add_argument("--sources", default="2")
    ap.add_argument("--exact-start", default=None, help="bench_solve's --exact-start R")
    ap.add_argument("mesh")
    ap.add_argument("builds", nargs="+", help="bench_solve binaries; the first is the reference")
    a = ap.parse_args()
    runs = {b: {} for b in a.builds}
    for r in range(a.rounds):
        for b in a.builds if r % 2 == 0 else a.builds[::-1]:
            cmd = [b, "--repeats", a.repeats, "--sources", a.sources]
            if a.exact_start:
                cmd += ["--exact-start", a.exact_start]
            out = subprocess.run(cmd + [a.mesh], capture_output=True, text=True, check=True).stdout
            for m in LINE.finditer(out):
                d = runs[b].setdefault(m.group(1), ([], [], [], []))
                for lst, g in zip(d, (2, 3, 4, 5)):
                    lst.append(float(m.group(g)))
    ref = runs[a.builds[0]]
    for u in sorted(ref, reverse=True):
        for b in a.builds:
            med, dij, mn, _ = runs[b][u]
            m, mm = statistics.median(med), min(mn)
            rel, relmin = m / statistics.median(ref[u][0]), mm / min(ref[u][2])
            print(f"{os.path.basename(a.mesh):22s} exact={a.exact_start or 0} unfolding={u} "
                  f"{name(b):14s} median {m:8.3f} ms ({rel:5.3f}x)  min {mm:8.3f} ms ({relmin:5.3f}x)"
                  f"  Dijkstra {statistics.median(dij):7.3f} ms  ratio {m / statistics.median(dij):4.2f}")


if __name__ == "__main__":
    main()
