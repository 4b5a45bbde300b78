"""The heat method of Crane, Weischedel & Wardetzky (2013) batched over many
sources: the strongest all-pairs peer (bench/suite/compare_allpairs.py).

Factor once with CHOLMOD (scikit-sparse), then per block of `block` sources:
heat flow (M + t L) U = delta_S, X = -grad U / |grad U| per face, Poisson
-L Phi = div X, rows = Phi shifted so each source is at 0. L and M are the
intrinsic Delaunay Laplacian and lumped mass of robust-laplacian (Sharp &
Crane 2020): the extrinsic cotan Laplacian gets some camelhead rows 15-121 %
wrong. Gradient and divergence are sparse products on the input faces, over
the whole block at once. |grad u| uses hypot: u underflows far from the
source, and squaring it would give 0/0.

    python bench/suite/heat_batched.py MESH [ROWS]     # a quick check against meshfmm

Needs scikit-sparse and robust-laplacian: run scripts/setup.sh --bench first.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.sparse as sp


def gradient_divergence(V: np.ndarray, F: np.ndarray):
    """G (3 nf x nv): per-face gradient of a vertex function, rows grouped as
    [x of all faces; y; z]. D (nv x 3 nf): the matching integrated divergence,
    D = -G^T A (A the face areas), so that D G is minus the cotan Laplacian."""
    nv, nf = V.shape[0], F.shape[0]
    P = V[F]  # (nf, 3, 3)
    N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    dbl = np.linalg.norm(N, axis=1)
    area = 0.5 * dbl
    n = N / np.where(dbl > 0, dbl, 1.0)[:, None]
    rows, cols, vals = [], [], []
    for k in range(3):
        e = P[:, (k + 2) % 3] - P[:, (k + 1) % 3]  # edge opposite corner k
        g = np.cross(n, e) / np.where(dbl > 0, dbl, np.inf)[:, None]  # grad of hat k
        for d in range(3):
            rows.append(d * nf + np.arange(nf))
            cols.append(F[:, k])
            vals.append(g[:, d])
    G = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(3 * nf, nv))
    A = sp.diags(np.tile(area, 3))
    D = (-(G.T @ A)).tocsr()
    return G, D


class BatchedHeat:
    def __init__(self, V: np.ndarray, F: np.ndarray, block: int = 32, t_factor: float = 1.0):
        import robust_laplacian
        from sksparse.cholmod import cholesky

        self.V = np.ascontiguousarray(V, dtype=np.float64)
        self.F = np.ascontiguousarray(F, dtype=np.int64)
        self.nv, self.nf = self.V.shape[0], self.F.shape[0]
        self.block = block
        L, M = robust_laplacian.mesh_laplacian(self.V, self.F)
        L = sp.csc_matrix(L)
        M = sp.csc_matrix(M)
        E = self.V[self.F]
        h = np.mean(np.linalg.norm(E - np.roll(E, 1, axis=1), axis=2))
        t = t_factor * h * h
        self.heat = cholesky(M + t * L)
        # L is singular (constants): a tiny shift, then each row is set to 0 at its source
        self.poisson = cholesky(L + 1e-10 * M)
        self.G, self.D = gradient_divergence(self.V, self.F)

    def rows(self, sources: np.ndarray, dtype=np.float32) -> np.ndarray:
        sources = np.asarray(sources, dtype=np.int64)
        out = np.empty((sources.size, self.nv), dtype=dtype)
        nf = self.nf
        for b0 in range(0, sources.size, self.block):
            s = sources[b0:b0 + self.block]
            k = s.size
            B = np.zeros((self.nv, k))
            B[s, np.arange(k)] = 1.0
            U = self.heat(B)
            GU = self.G @ U  # (3 nf, k)
            gx, gy, gz = GU[:nf], GU[nf:2 * nf], GU[2 * nf:]
            norm = np.hypot(np.hypot(gx, gy), gz)
            inv = np.divide(-1.0, norm, out=np.zeros_like(norm), where=norm > 0)
            X = np.concatenate((gx * inv, gy * inv, gz * inv))
            divX = self.D @ X
            Phi = self.poisson(-divX)  # L is minus the Laplacian (positive semi-definite)
            Phi -= Phi[s, np.arange(k)][None, :]
            out[b0:b0 + k] = Phi.T
        return out


def main() -> None:
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
    import benchlib as bl
    import meshfmm

    name = sys.argv[1] if len(sys.argv) > 1 else "camelhead.off"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    V, F = meshfmm.load_mesh(bl.DATA / "meshes" / name)
    V, F, _, _ = bl.compact(V, F)
    t0 = time.perf_counter()
    h = BatchedHeat(V, F)
    t1 = time.perf_counter()
    rows = (np.arange(n) * V.shape[0]) // n
    R = h.rows(rows)
    t2 = time.perf_counter()
    m = meshfmm.Mesh(V, F)
    t3 = time.perf_counter()
    D = m.distance_matrix(rows, backend="serial")
    t4 = time.perf_counter()
    pos = D > 0
    rel = np.abs(R[pos] - D[pos]) / D[pos]
    print(f"{name}: nv {V.shape[0]}, {n} rows; heat precompute {t1 - t0:.2f} s, rows "
          f"{n * V.shape[0] / (t2 - t1) / 1e6:.2f} M entries/s; meshfmm serial "
          f"{n * V.shape[0] / (t4 - t3) / 1e6:.2f} M/s; mean rel. difference "
          f"{100 * rel.mean():.2f} %")


if __name__ == "__main__":
    main()
