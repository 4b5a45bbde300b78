"""How well do distance matrices compress? Distance-matrix chunks through the
Zarr codecs meshfmm.distributed can use (Blosc: zstd, lz4, blosclz; byte or
bit shuffle; levels), on rows of real meshes (tests/data/meshes), float32 and float64.

    MESHFMM_LIBRARY=build/libmeshfmm.so PYTHONPATH=bindings/python \
        python bench/scale/bench_compression.py [--rows 256] [--meshes a.off,b.obj]

Each mesh: `--rows` contiguous rows (sources k..k+rows-1, as a task's chunk
holds them) at a random offset, cut into chunks of the shape
meshfmm.distributed picks by default (about 8 MiB). Encode and decode run
single-threaded (numcodecs' Blosc without its own threads: what a Dask task
gets), best of 3. The ratio is raw bytes / encoded bytes over all chunks.
"xor_prev_row" (the bits of each row XOR the previous row's, then zstd 1 +
bitshuffle) is measured as an idea only: readers would need meshfmm's own
codec. Writes bench/results/compression.json."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numcodecs
import numpy as np
from numcodecs import Blosc

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # bench/
import benchlib  # noqa: E402
import meshfmm  # noqa: E402

numcodecs.blosc.use_threads = False

# (name, cname, clevel, shuffle); the first is meshfmm.distributed's default
CODECS = [
    ("lz4 bitshuffle", "lz4", 5, Blosc.BITSHUFFLE),
    ("zstd 3 byte shuffle", "zstd", 3, Blosc.SHUFFLE),
    ("zstd 1 byte shuffle", "zstd", 1, Blosc.SHUFFLE),
    ("zstd 1 bitshuffle", "zstd", 1, Blosc.BITSHUFFLE),
    ("zstd 3 bitshuffle", "zstd", 3, Blosc.BITSHUFFLE),
    ("zstd 5 bitshuffle", "zstd", 5, Blosc.BITSHUFFLE),
    ("lz4 byte shuffle", "lz4", 5, Blosc.SHUFFLE),
    ("blosclz bitshuffle", "blosclz", 5, Blosc.BITSHUFFLE),
]
MESHES = ["hand_lowres.obj", "spot.obj", "fertility_FE_10k.off", "camelhead.off",
          "nefertiti-lowres.obj", "stanford-bunny.obj", "igea.ply"]
CHUNK_BYTES = 8 << 20  # meshfmm.distributed._BLOCK_BYTES


def best(fn, n=3):
    t = float("inf")
    out = None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        t = min(t, time.perf_counter() - t0)
    return out, t


def xor_prev_row(c: np.ndarray) -> np.ndarray:
    u = c.view(np.uint32 if c.itemsize == 4 else np.uint64)
    x = u.copy()
    x[1:] ^= u[:-1]
    return x


def measure(D: np.ndarray) -> list:
    """Ratio and single-thread MB/s of every codec on the chunks of D."""
    chunk_rows = max(1, min(D.shape[0], CHUNK_BYTES // (D.shape[1] * D.itemsize)))
    chunks = [np.ascontiguousarray(D[r:r + chunk_rows]) for r in range(0, D.shape[0], chunk_rows)]
    raw = D.nbytes
    out = []
    for name, cname, lvl, sh in CODECS + [("xor_prev_row + zstd 1 bitshuffle", "zstd", 1,
                                           Blosc.BITSHUFFLE)]:
        codec = Blosc(cname=cname, clevel=lvl, shuffle=sh, blocksize=0)
        pre = xor_prev_row if name.startswith("xor") else (lambda c: c)
        enc, te = best(lambda: [codec.encode(pre(c)) for c in chunks])
        _, td = best(lambda: [codec.decode(e) for e in enc])
        n = sum(len(e) for e in enc)
        out.append({"codec": name, "ratio": raw / n, "encode_mb_s": raw / te / 1e6,
                    "decode_mb_s": raw / td / 1e6, "chunk_rows": chunk_rows})
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=256, help="rows per mesh (64 above 50k vertices)")
    ap.add_argument("--meshes", default=",".join(MESHES))
    a = ap.parse_args()
    rng = np.random.default_rng(11)
    res = {"machine": benchlib.machine_info(), "versions": benchlib.versions(),
           "blosc_threads": 1, "chunk_bytes": CHUNK_BYTES, "meshes": []}
    for name in a.meshes.split(","):
        mesh = meshfmm.Mesh(*meshfmm.load_mesh(str(benchlib.DATA / "meshes" / name)))
        nv = mesh.n_vertices
        rows = min(nv, a.rows if nv <= 50_000 else min(a.rows, 64))
        r0 = int(rng.integers(0, nv - rows + 1))
        src = np.arange(r0, r0 + rows, dtype=np.int32)
        entry = {"mesh": name, "n_vertices": nv, "rows": rows, "first_row": r0}
        for dt in ("float32", "float64"):
            D = mesh.distance_matrix(src, backend="threads", dtype=dt)
            entry[dt] = measure(D)
            for m in entry[dt]:
                print(f"{name:22s} {dt} {m['codec']:34s} ratio {m['ratio']:.3f}  "
                      f"enc {m['encode_mb_s']:6.0f} MB/s  dec {m['decode_mb_s']:6.0f} MB/s",
                      flush=True)
        res["meshes"].append(entry)
    # geometric means over the meshes, per dtype and codec
    summary = {}
    for dt in ("float32", "float64"):
        summary[dt] = []
        for i, (name, *_r) in enumerate(CODECS + [("xor_prev_row + zstd 1 bitshuffle",)]):
            vals = [m[dt][i] for m in res["meshes"]]
            g = {k: float(np.exp(np.mean(np.log([v[k] for v in vals]))))
                 for k in ("ratio", "encode_mb_s", "decode_mb_s")}
            summary[dt].append({"codec": name, **g})
    res["geomean"] = summary
    out = benchlib.RESULTS / "compression.json"
    out.write_text(json.dumps(res, indent=1) + "\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
