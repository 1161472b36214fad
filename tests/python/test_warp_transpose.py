"""cadmorph.Warp.apply_transpose, the warp's reverse product: the dot-product test
<V, apply(D)> = <apply_transpose(V), D> through the package for each method, in the row
layout of apply's D (constrained nodes given unsorted, interior ones among them), and the
checks of V before the library sees it."""
import numpy as np
import pytest

import cadmorph
from morph_helpers import bore


@pytest.fixture(scope="module")
def bore_mesh(cli, tmp_path_factory):
    """The bore's hex mesh at scale 0.5 (4752 nodes, 1728 on the boundary)."""
    work = tmp_path_factory.mktemp("warp_transpose_bore")
    return bore(cli, work, [])[0]


def pinned_nodes(mesh: cadmorph.Mesh) -> np.ndarray:
    """Some interior nodes, then the boundary nodes: unsorted, so that a wrong row order of
    apply_transpose shows."""
    b = cadmorph.Warp(mesh, method="femwarp", progress=False).nodes
    interior = np.setdiff1d(np.arange(mesh.n_nodes), b)[::97]
    return np.concatenate([interior, b])


def dot_error(w: cadmorph.Warp, seed: int) -> float:
    """|<V, J D> - <J^T V, D>| relative to sum |V J D| (a random sum can cancel, its terms
    cannot), for random D and V."""
    rng = np.random.default_rng(seed)
    D = rng.uniform(-1, 1, (len(w.nodes), 3))
    V = rng.uniform(-1, 1, (w.n_nodes, 3))
    JD = w.apply(D)
    JtV = w.apply_transpose(V)
    assert JtV.shape == D.shape and JtV.dtype == np.float64
    return abs(np.vdot(V, JD) - np.vdot(JtV, D)) / np.abs(V * JD).sum()


@pytest.mark.parametrize("method", ["femwarp", "lbwarp", "simplex", "dmffd", "mls"])
def test_apply_transpose_is_the_transpose_of_apply(bore_mesh, method):
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, pinned_nodes(mesh), method=method, progress=False)
    assert dot_error(w, 1) <= 1e-10
    assert dot_error(w, 2) <= 1e-10


# The RBF warps: dense, and iterative at a tolerance tight enough for the dot-product test to
# hold at 1e-10 (the reverse product is the weights of a solve: docs/DESIGN.md, "Gradients").
@pytest.mark.parametrize("method", ["rbf", "rbf-biharmonic"])
def test_apply_transpose_rbf(bore_mesh, method):
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, pinned_nodes(mesh), method=method, solver="dense", progress=False)
    assert dot_error(w, 3) <= 1e-10


def test_apply_transpose_rbf_iterative(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, pinned_nodes(mesh), solver="iterative", tolerance=1e-13,
                      progress=False)
    assert dot_error(w, 4) <= 1e-10


def test_apply_transpose_layout_and_array_likes(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    nodes = pinned_nodes(mesh)
    w = cadmorph.Warp(mesh, nodes, method="lbwarp", progress=False)
    rng = np.random.default_rng(4)
    V = rng.uniform(-1, 1, (mesh.n_nodes, 3))
    out = w.apply_transpose(V)
    # row k belongs to nodes[k]: the warp of the same nodes in ascending order gives the
    # same rows, permuted
    order = np.argsort(nodes)
    sorted_w = cadmorph.Warp(mesh, nodes[order], method="lbwarp", progress=False)
    assert np.allclose(sorted_w.apply_transpose(V), out[order], rtol=1e-12, atol=1e-14)
    assert np.array_equal(w.apply_transpose(V.tolist()), out)  # lists
    assert np.array_equal(w.apply_transpose(np.asfortranarray(V)), out)  # any layout
    assert np.array_equal(w.apply_transpose(V), out)  # the same again, bit for bit
    # V at a node apply writes 0 to does not matter; a unit V at one interior node is that
    # node's row of J, spread over the constrained nodes it depends on
    e = np.zeros((mesh.n_nodes, 3))
    free = np.setdiff1d(np.arange(mesh.n_nodes), nodes)[10]
    e[free, 0] = 1
    row = w.apply_transpose(e)
    D = rng.uniform(-1, 1, (len(nodes), 3))
    assert np.isclose(np.vdot(row, D), w.apply(D)[free, 0], rtol=1e-10, atol=1e-14)


def test_apply_transpose_bad_arrays_raise_before_the_library(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    n = mesh.n_nodes
    w = cadmorph.Warp(mesh, method="femwarp", progress=False)
    k = len(w.nodes)
    with pytest.raises(ValueError, match=r"V must have shape \(%d, 3\), not \(%d, 3\)" % (n, k)):
        w.apply_transpose(np.zeros((k, 3)))  # every node, not the constrained ones
    with pytest.raises(ValueError, match="shape"):
        w.apply_transpose(np.zeros(3 * n))
    with pytest.raises(TypeError, match="real numbers"):
        w.apply_transpose(np.zeros((n, 3), complex))
    bad = np.zeros((n, 3))
    bad[12, 2] = np.nan
    with pytest.raises(ValueError, match="V row 12 is not finite"):
        w.apply_transpose(bad)
