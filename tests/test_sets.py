"""`cnem._sets`: the sort-based set operations equal numpy's on every shape and dtype."""
import numpy as np
import pytest

from cnem._sets import distinct, isin


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.uint8, bool, np.float64])
@pytest.mark.parametrize("shape", [(0,), (1,), (7,), (50, 3), (4, 5, 6)])
def test_distinct_and_isin_equal_numpy(dtype, shape):
    rng = np.random.default_rng(sum(shape))
    values = rng.integers(-5 if np.dtype(dtype).kind == "i" else 0, 40, size=shape).astype(dtype)
    table = rng.integers(0, 40, size=(13, 2)).astype(dtype)
    got = distinct(values)
    np.testing.assert_array_equal(got, np.unique(values))
    assert got.dtype == np.unique(values).dtype
    np.testing.assert_array_equal(isin(values, table), np.isin(values, table))
    np.testing.assert_array_equal(isin(values, table[:0]), np.isin(values, table[:0]))
    assert isin(values, table).shape == values.shape


def test_large_keys_and_mixed_integer_kinds():
    rng = np.random.default_rng(3)
    keys = rng.integers(0, 2 ** 62, 10_000)
    probe = np.concatenate([rng.choice(keys, 500), rng.integers(0, 2 ** 62, 500)])
    np.testing.assert_array_equal(distinct(keys), np.unique(keys))
    np.testing.assert_array_equal(isin(probe, keys), np.isin(probe, keys))
    small = np.array([1, 2, 300], dtype=np.int32)
    np.testing.assert_array_equal(isin(small, np.array([300, 7], dtype=np.int64)),
                                  [False, False, True])
