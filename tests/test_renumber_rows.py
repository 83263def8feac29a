"""`cnem.assembly.gradient_update.renumber_rows` against a dense reference."""

import numpy as np
import pytest
import scipy.sparse as sp

from cnem.assembly.gradient_update import renumber_rows
from cnem.errors import CNEMError


def _case(seed):
    rng = np.random.default_rng(seed)
    A = sp.random(40, 30, density=0.2, random_state=seed, format="csr")
    rows = rng.integers(-1, 40, 25)                       # -1: an empty row
    columns = rng.permutation(35)[:30]                    # into 35 new columns
    columns[rng.random(30) < 0.2] = -1                    # columns without a new index
    return A, rows, columns


@pytest.mark.parametrize("seed", range(5))
def test_rows_and_columns_as_the_dense_reference(seed):
    A, rows, columns = _case(seed)
    out = renumber_rows(A, rows, columns, (25, 35), drop=True)
    ref = np.zeros((25, 35))
    dense = A.toarray()
    for r, i in enumerate(rows):
        if i >= 0:
            keep = columns >= 0
            ref[r, columns[keep]] = dense[i, keep]
    np.testing.assert_array_equal(out.toarray(), ref)
    assert out.has_sorted_indices
    for r in range(25):                                   # sorted inside every row
        assert np.all(np.diff(out.indices[out.indptr[r]:out.indptr[r + 1]]) > 0)


def test_a_copied_entry_without_a_column_raises_unless_dropped():
    A, rows, columns = _case(0)
    with pytest.raises(CNEMError, match="no new index"):
        renumber_rows(A, rows, columns, (25, 35))
    kept = np.where(columns >= 0, columns, 0)             # every column has one: no error
    assert renumber_rows(A, rows, kept, (25, 35)).shape == (25, 35)
