"""A wrapping label keeps each figure with its unit; the words themselves stay as they were."""

from __future__ import annotations

from fha_studio.gui.unit_spacing import units_kept

NBSP = "\u00a0"


def test_a_number_and_its_unit_are_joined_for_the_page_only():
    said = "move test of 30° at 30 r/min done; 5 records of 4092 samples (4.8 s), current at most 3.25 A"
    shown = units_kept(said)
    assert shown == ("move test of 30° at 30\u00a0r/min done; 5 records of 4092 samples (4.8\u00a0s), "
                     "current at most 3.25\u00a0A")
    assert shown.replace(NBSP, " ") == said  # nothing else changes
    assert said.count(NBSP) == 0  # the text it was given (a file's, the logic's) keeps its spaces


def test_every_unit_the_pages_print_is_joined_and_nothing_that_only_starts_like_one():
    for figure in ("12.3 ms", "22 Hz", "2.5 kHz", "2.00 %", "28.3 N·m", "0.81 kg·m²", "40 arc-sec",
                   "2.5 °/s", "0.32 r/min", "3.5 rad/s", "1 mA", "5 V"):
        assert units_kept(f"({figure})") == f"({figure.replace(' ', NBSP, 1)})", figure
    for words in ("4 servo periods", "5 samples", "limit switch 2 (CW end)", "parameter 8 = 0",
                  "bits of 4 Apples", "2 s/rad", "the 3 x case", "1 count"):
        assert units_kept(words) == words, words
