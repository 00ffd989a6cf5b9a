"""The DGR checks' rotary direction (FHA-C manual 1-10) in a technician's words."""

from __future__ import annotations

from fha_studio.logic.absolute import rotary_direction_check


def test_the_rotary_direction_check_says_the_change_in_counts_and_degrees_in_one_parenthesis():
    # ratio 50, 8192 counts a motor turn: +5689 counts is +5.00° at the output
    passed, words, values = rotary_direction_check(11378, 11378 + 5689, 0, 50)
    assert passed is True and values["turned"] == "CW"
    assert words == ("the FWD command turned the output CW seen from the flange (+5689 counts, +5.00°): "
                     "as parameter 8 = 0 says")
    passed, words, _ = rotary_direction_check(100, 40, 0, None)  # no ratio known: counts alone
    assert passed is False and "(-60 counts), but parameter 8 = 0 says CW" in words
