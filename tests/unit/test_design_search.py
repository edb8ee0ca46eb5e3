"""The ply search finds the threshold of any monotone outcome with few evaluations."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wovenimpact.errors import InputError
from wovenimpact.studies.design import search_plies


@given(threshold=st.integers(1, 40), start=st.integers(1, 8))
def test_search_finds_the_smallest_stopping_pack(threshold, start):
    calls = []

    def stops(batch):
        calls.append(list(batch))
        return {n: n >= threshold for n in batch}

    n, seen = search_plies(stops, start=start)
    assert n == threshold
    assert seen[n] and (n == 1 or seen.get(n - 1) is False or n - 1 < 1 or n - 1 not in seen
                        or not seen[n - 1])
    assert n - 1 == 0 or (n - 1) in seen  # the answer is bracketed by runs
    assert len(calls) <= 12


def test_search_gives_up_past_the_limit():
    with pytest.raises(InputError, match="no pack"):
        search_plies(lambda batch: {n: False for n in batch}, max_plies=16)


def test_a_larger_pack_that_perforates_is_reported():
    """Near a ballistic limit the simulated outcome need not be monotonic (seen before
    the contact-stiffness fix: 175 m/s FSP, 5 and 8 plies stopped it, 7 did not): the
    answer comes with a warning."""
    from wovenimpact.studies.design import monotonic_warning

    assert monotonic_warning(5, {1: False, 2: False, 4: False, 5: True, 8: True}) == ""
    text = monotonic_warning(5, {1: False, 2: False, 4: False, 5: True, 7: False, 8: True})
    assert text.startswith("7 plies did not stop the impactor although 5 did")
