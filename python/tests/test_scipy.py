"""The linkage matrix works with scipy.cluster.hierarchy (Debian's python3-scipy)."""

import numpy as np
import pytest

import primseg
from conftest import capped_cylinder, same_partition

hierarchy = pytest.importorskip("scipy.cluster.hierarchy")


@pytest.fixture(scope="module")
def fandisk_tree(fandisk):
    return primseg.segment(primseg.read_mesh(fandisk))


def test_valid_linkage(fandisk_tree):
    Z = fandisk_tree.linkage()
    F = fandisk_tree.face_count
    assert Z.shape == (F - 1, 4) and Z.dtype == np.float64
    assert hierarchy.is_valid_linkage(Z, throw=True)
    assert hierarchy.num_obs_linkage(Z) == F
    assert hierarchy.to_tree(Z).get_count() == F
    np.testing.assert_array_equal(np.sort(hierarchy.leaves_list(Z)), np.arange(F))


@pytest.mark.parametrize("k", [1, 2, 7, 30, 500])
def test_cut_tree_gives_the_same_levels(fandisk_tree, k):
    Z = fandisk_tree.linkage()
    assert hierarchy.is_monotonic(Z)
    labels = fandisk_tree.cut(k)
    assert same_partition(hierarchy.cut_tree(Z, n_clusters=k)[:, 0], labels)
    assert same_partition(hierarchy.fcluster(Z, k, criterion="maxclust"), labels)


def test_dendrogram_of_the_top_levels(fandisk_tree):
    tree = hierarchy.dendrogram(fandisk_tree.linkage(), truncate_mode="lastp", p=12, no_plot=True)
    assert len(tree["leaves"]) == 12
    assert sum(int(label.strip("()")) if label.startswith("(") else 1 for label in tree["ivl"]) == fandisk_tree.face_count


def test_components_are_joined_last_above_every_cost():
    V, F, _ = capped_cylinder()
    # Two disjoint copies: two components, joined by one trailing merge.
    V2 = np.vstack([V, V + [100, 0, 0]])
    F2 = np.vstack([F, F + len(V)])
    h = primseg.segment(V2, F2)
    assert h.component_count == 2
    Z = h.linkage()
    assert hierarchy.is_valid_linkage(Z)
    assert Z[-1, 2] > Z[:-1, 2].max() and Z[-1, 3] == len(F2)
    assert h.cut(1).max() == 1  # a cut never applies the trailing merge
    first = h.cut(2)
    assert same_partition(first, np.repeat([0, 1], len(F)))
    assert same_partition(hierarchy.cut_tree(Z, n_clusters=2)[:, 0], first)
