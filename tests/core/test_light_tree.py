"""The light tree over emissive triangles: its build, and that its picks follow its pmf."""
import numpy as np
import pytest

from mcengine.kernels.light_tree import (
    LEAF_SIZE,
    S_CENTRE,
    S_POWER,
    S_RADIUS2,
    build_emitter_tree,
    tree_pick,
    tree_pmf,
)


def random_triangles(n, seed, spread=4.0, size=0.3):
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-spread, spread, (n, 1, 3))
    corners = centres + rng.normal(scale=size, size=(n, 3, 3))
    power = rng.uniform(0.1, 3.0, n)
    power[rng.random(n) < 0.1] = 0.0           # some triangles give no light (estimate 0)
    return corners, power


def receivers(seed, count=12):
    """Points with and without a normal (0: a surface that transmits)."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        p = rng.uniform(-5.0, 5.0, 3)
        n = np.zeros(3) if k % 4 == 0 else rng.normal(size=3)
        if k % 4:
            n /= np.linalg.norm(n)
        out.append((float(p[0]), float(p[1]), float(p[2]), float(n[0]), float(n[1]), float(n[2])))
    return out


@pytest.mark.parametrize("n", [1, 3, 4, 5, 37, 600])
def test_every_triangle_sits_in_one_leaf_and_every_node_bounds_its_triangles(n):
    corners, power = random_triangles(n, seed=n)
    tree = build_emitter_tree(corners, power)
    assert sorted(tree.order[tree.order >= 0]) == list(range(n))
    np.testing.assert_array_equal(tree.order[tree.rank], np.arange(n))
    nodes = tree.nodes
    leaves = (len(nodes) + 1) // 2
    assert len(tree.order) == leaves * LEAF_SIZE and leaves & (leaves - 1) == 0
    np.testing.assert_allclose(nodes[0, S_POWER], power.sum())
    for leaf in range(leaves):
        members = [j for j in tree.order[leaf * LEAF_SIZE:(leaf + 1) * LEAF_SIZE] if j >= 0]
        k = leaves - 1 + leaf
        while True:        # the leaf and each of its ancestors hold the members' corners
            if members and nodes[k, S_POWER] > 0.0:
                d2 = np.sum((corners[members].reshape(-1, 3) - nodes[k, S_CENTRE:S_CENTRE + 3]) ** 2,
                            axis=1)
                assert np.all(d2 <= nodes[k, S_RADIUS2] * (1 + 1e-12))
            if k == 0:
                break
            k = (k - 1) // 2


@pytest.mark.parametrize("n", [1, 6, 37, 600])
def test_picks_follow_the_pmf_which_sums_to_one_where_no_normal_cuts_it(n):
    """Evenly spaced numbers u pick each triangle in the share of [0, 1) its pmf says (the
    tree maps u to one interval per triangle), tree_pick's pmf is tree_pmf's, and the pmf
    sums to 1 at receivers without a normal; with one it may sum to less: a node's sphere
    can reach in front of the surface where its children's lie wholly behind it (nothing
    there can light the receiver, and the pick returns none)."""
    corners, power = random_triangles(n, seed=100 + n)
    tree = build_emitter_tree(corners, power)
    count = 20000
    for recv in receivers(seed=n):
        pmf = np.array([tree_pmf(tree, j, recv) for j in range(n)])
        assert np.all(np.isfinite(pmf)) and np.all(pmf >= 0.0)
        assert np.all(pmf[power == 0.0] == 0.0)
        hits = np.zeros(n)
        for i in range(count):
            j, p = tree_pick(tree, recv, (i + 0.5) / count)
            if j < 0:
                assert p == 0.0
                continue
            assert p == pytest.approx(pmf[j], rel=1e-9)
            hits[j] += 1
        if pmf.sum() == 0.0:
            assert hits.sum() == 0
            continue
        if any(recv[3:]):
            assert pmf.sum() <= 1.0 + 1e-9
        else:
            assert pmf.sum() == pytest.approx(1.0, rel=1e-9)
        np.testing.assert_allclose(hits / count, pmf, atol=2.0 / count)


def test_no_triangle_reaching_in_front_of_the_receiver_has_pmf_zero():
    corners, power = random_triangles(300, seed=7, size=0.5)
    power[:] = 1.0
    tree = build_emitter_tree(corners, power)
    for recv in receivers(seed=8, count=16):
        p, n = np.array(recv[:3]), np.array(recv[3:])
        in_front = np.any((corners - p) @ n > 1e-9, axis=1) if n.any() else np.ones(300, bool)
        pmf = np.array([tree_pmf(tree, j, recv) for j in range(300)])
        assert np.all(pmf[in_front] > 0.0)


def test_a_nearer_triangle_is_picked_more_often():
    tri = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]])
    corners = np.stack([tri + (0.0, 0.0, 1.0), tri + (0.0, 0.0, 10.0)])
    tree = build_emitter_tree(corners, np.ones(2))
    recv = (0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    near, far = tree_pmf(tree, 0, recv), tree_pmf(tree, 1, recv)
    assert near + far == pytest.approx(1.0)
    assert near > 50.0 * far
