"""Virtual edges (section 4.2's unfolding) are lengths of real paths: the
straight segment from an obtuse corner to its virtual vertex crosses every
edge of the unfolded strip, so no march value falls below the straight line
through space."""
import numpy as np

import meshfmm
from conftest import DATA


def test_a_strip_that_folds_back_gives_no_virtual_edge():
    # two flat pages on one spine, folded 66 degrees, 67 vertices: a strip
    # unfolded from one corner folded back over itself and put the virtual
    # vertex 1167 from the corner, where the straight line is 2896 and the
    # surface's shortest path 4966
    d = np.load(DATA / "oracles" / "book_strip_folds_back.npz")
    V, F, s = d["V"], d["F"], int(d["source"])
    m = meshfmm.Mesh(V, F)
    assert m.info.n_virtual_edges + m.info.n_unfold_failures == m.info.n_obtuse_corners
    euclid = np.linalg.norm(V - V[s], axis=1)
    for kwargs in ({"exact_start": False}, {}):
        d = m.distance(s, **kwargs)
        assert np.all(d >= euclid * (1 - 1e-12)), kwargs
