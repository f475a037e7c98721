"""paper_rate: a velocity as V whole pixels every P ticks, exact from the decimal written."""

import pytest

from collide2d.engine.motion import MAX_PERIOD_TICKS, paper_rate


@pytest.mark.parametrize(
    "v, fps, expected",
    [
        (10, 10, (1, 1)),
        (5, 10, (1, 2)),
        (7.5, 10, (3, 4)),
        (-7.5, 10, (-3, 4)),
        (0, 10, (0, 1)),
        (10, 1, (10, 1)),
        (0.1, 10, (1, 100)),
        (33, 60, (11, 20)),
        (2.5, 1, (5, 2)),
    ],
)
def test_rates_in_lowest_terms(v, fps, expected):
    assert paper_rate(v, fps) == expected


def test_decimal_is_read_as_written_not_as_binary_float():
    # 0.1 is 0x3FB999999999999A in binary; the user meant one tenth
    assert paper_rate(0.1, 1) == (1, 10)


@pytest.mark.parametrize("v", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_is_refused(v):
    with pytest.raises(ValueError, match="finite"):
        paper_rate(v, 10)


def test_a_period_past_the_bound_is_refused_with_the_reason():
    with pytest.raises(ValueError, match="whole number of pixels per whole number of ticks"):
        paper_rate(1e-7, 10)
    V, P = paper_rate(1 / 2**10, 1)  # 2**-10 is exact and within the bound
    assert (V, P) == (1, 1024) and P <= MAX_PERIOD_TICKS
