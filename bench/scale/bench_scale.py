"""Matrices at scale: sparse local rows/s as N grows, landmark S x T against
full rows, and the sparse local matrix against gdist.local_gdist_matrix
(skipped when gdist does not import: scripts/setup.sh --bench installs it).

    MESHFMM_LIBRARY=build/libmeshfmm.so PYTHONPATH=bindings/python \
        python bench/scale/bench_scale.py [--quick] [--threads 1]

Writes bench/results/scale.json. Everything in one run, so ratios compare
like with like on a shared machine (absolute numbers move with the load)."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib  # noqa: E402
import meshfmm  # noqa: E402


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def sparse_rows(mesh, radii_edges, n_rows, threads, rng):
    h = mesh.info.mean_edge_length
    src = rng.choice(mesh.n_vertices, size=n_rows, replace=False).astype(np.int32)
    # warm-up: first-call costs (imports, page faults, the mesh's exact tables,
    # built once per mesh) are not rows
    mesh.distance_matrix(src[:8], max_distance=5 * h, sparse=True, backend="threads",
                         n_threads=threads)
    out = []
    for k in radii_edges:
        for start in ("exact", "plain"):  # the default exact start, and the paper's
            (S, info), dt = timed(lambda: mesh.distance_matrix(
                src, max_distance=k * h, sparse=True, backend="threads", n_threads=threads,
                exact_start=start == "exact", return_info=True))
            out.append({"r_edges": k, "start": start, "rows": n_rows, "seconds": dt,
                        "rows_per_s": n_rows / dt, "nnz_per_row": S.nnz / n_rows,
                        "vertices_settled_per_row": info.vertices_settled / n_rows})
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(11)
    work = Path(tempfile.mkdtemp(prefix="mfmm_scale_"))
    res = {"machine": benchlib.machine_info(), "versions": benchlib.versions(),
           "threads": a.threads, "sparse_vs_n": [], "landmarks": None, "gdist": None}

    # (a) sparse local rows/s at r = 5 and 20 mean edge lengths, N ~ 100k and ~1M
    sizes = [100, 316] if a.quick else [316, 1000]
    for n in sizes:
        mesh = meshfmm.Mesh(*benchlib.generate("sine", n, work))
        rows = 200 if a.quick else 1000
        r = sparse_rows(mesh, [5, 20], rows, a.threads, rng)
        res["sparse_vs_n"].append({"mesh": f"sine {n}", "n_vertices": mesh.n_vertices, "radii": r})
        for x in r:
            print(f"sine {n:5d} nv={mesh.n_vertices:8d} r={x['r_edges']:2d} h: "
                  f"{x['rows_per_s']:9.0f} rows/s, {x['nnz_per_row']:7.0f} entries/row", flush=True)

    # (b) 1000 x 1000 landmarks against full rows (a sample of full rows: per-row time)
    n = 100 if a.quick else 316
    mesh = meshfmm.Mesh(*benchlib.generate("sine", n, work))
    n_land = 200 if a.quick else 1000
    land = rng.choice(mesh.n_vertices, size=n_land, replace=False).astype(np.int32)
    (L, info), t_land = timed(lambda: mesh.distance_matrix(
        land, targets=land, backend="threads", n_threads=a.threads, return_info=True))
    settled_land = info.vertices_settled
    n_full = 50 if a.quick else 100
    (_, info), t_full = timed(lambda: mesh.distance_matrix(
        land[:n_full], backend="threads", n_threads=a.threads, return_info=True))
    settled_full = info.vertices_settled
    per_land, per_full = t_land / n_land, t_full / n_full
    res["landmarks"] = {"mesh": f"sine {n}", "n_vertices": mesh.n_vertices, "landmarks": n_land,
                        "landmark_seconds_per_row": per_land, "full_seconds_per_row": per_full,
                        "speedup_per_row": per_full / per_land,
                        "settled_per_row_landmarks": settled_land / n_land,
                        "settled_per_row_full": settled_full / n_full}
    # landmarks in one region (the n_land vertices nearest to one point): rows stop early
    V = mesh.vertices
    near = np.argsort(np.linalg.norm(V - V[land[0]], axis=1))[:n_land].astype(np.int32)
    (_, info), t_near = timed(lambda: mesh.distance_matrix(
        near, targets=near, backend="threads", n_threads=a.threads, return_info=True))
    settled_near = info.vertices_settled
    res["landmarks"].update({"clustered_seconds_per_row": t_near / n_land,
                             "clustered_speedup_per_row": per_full / (t_near / n_land),
                             "settled_per_row_clustered": settled_near / n_land})
    print(f"clustered landmarks {n_land}x{n_land}: {t_near/n_land*1e3:.3f} ms/row: "
          f"{per_full/(t_near/n_land):.1f}x (settled {settled_near/n_land:.0f} per row)", flush=True)
    print(f"landmarks {n_land}x{n_land} on nv={mesh.n_vertices}: {per_land*1e3:.2f} ms/row vs "
          f"full {per_full*1e3:.2f} ms/row: {per_full/per_land:.2f}x "
          f"(settled {settled_land/n_land:.0f} vs {settled_full/n_full:.0f} per row)", flush=True)

    # (c) sparse all-pairs within r against gdist.local_gdist_matrix (same mesh, radius)
    try:
        import gdist
    except Exception as exc:  # not installed, or a binary built for another numpy
        res["gdist"] = {"skipped": f"gdist does not import: {exc}"}
        print("gdist: skipped:", exc)
    else:
        n = 40 if a.quick else 70
        mesh = meshfmm.Mesh(*benchlib.generate("sine", n, work))
        V, F = mesh.vertices, mesh.faces
        r = 5 * mesh.info.mean_edge_length
        S, t_m = timed(lambda: mesh.distance_matrix(None, max_distance=r, sparse=True,
                                                    dtype="float64", backend="threads",
                                                    n_threads=a.threads))
        G, t_g = timed(lambda: gdist.local_gdist_matrix(np.ascontiguousarray(V, np.float64),
                                                        np.ascontiguousarray(F, np.int32), r))
        G = G.tocsr()
        A = S.copy()
        A.data[:] = 1
        B = G.copy()
        B.data[:] = 1
        B.setdiag(1)  # gdist stores no diagonal; meshfmm's zeros are explicit
        both = A.multiply(B).nnz
        union = (A + B).nnz
        C = A.multiply(B).tocsr()  # pairs both hold (off the diagonal: both > 0)
        Sm = S.multiply(C).tocsr()
        Gm = G.multiply(C).tocsr()
        Sm.sort_indices()
        Gm.sort_indices()
        assert np.array_equal(Sm.indices, Gm.indices) and np.array_equal(Sm.indptr, Gm.indptr)
        rel = np.abs(Sm.data - Gm.data)
        gvals = Gm.data
        res["gdist"] = {"mesh": f"sine {n}", "n_vertices": mesh.n_vertices, "r_edges": 5,
                        "meshfmm_seconds": t_m, "gdist_seconds": t_g, "speedup": t_g / t_m,
                        "meshfmm_entries_per_s": S.nnz / t_m, "gdist_entries_per_s": G.nnz / t_g,
                        "meshfmm_nnz": int(S.nnz), "gdist_nnz_with_diagonal": int(B.nnz),
                        "pattern_jaccard": both / union,
                        "mean_rel_diff_common": float(np.mean(rel / gvals))}
        print(f"gdist on nv={mesh.n_vertices}, r=5h: meshfmm {t_m:.2f} s, gdist {t_g:.2f} s "
              f"({t_g/t_m:.1f}x); pattern Jaccard {both/union:.4f}; "
              f"mean rel diff {np.mean(rel/gvals)*100:.2f} %", flush=True)

    out = benchlib.RESULTS / "scale.json"
    out.write_text(json.dumps(res, indent=1) + "\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
