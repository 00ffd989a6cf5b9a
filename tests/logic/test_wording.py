"""A sentence's ASCII units as the manual prints them, for a page (wording.manual_units_in_text)."""

from __future__ import annotations

import pytest

from fha_studio.logic.wording import manual_units_in_text


@pytest.mark.parametrize(("ascii_text", "page_text"), [
    ("(on the declared inertia 0.67 kg m^2)", "(on the declared inertia 0.67 kg·m²)"),
    ("Coulomb friction 2.5 N m ± 0.1", "Coulomb friction 2.5 N·m ± 0.1"),
    ("drag 0.2 N m s/rad, stiffness 3e4 N m/rad", "drag 0.2 N·m·s/rad, stiffness 3e4 N·m/rad"),
    ("torques in N m rest on it; 10 N m, 5 N m.", "torques in N·m rest on it; 10 N·m, 5 N·m."),
    ("gravity 7.8 N m (phase 30.0 deg)", "gravity 7.8 N·m (phase 30.0°)"),
    ("12 arcsec rms, 4 rad/s^2", "12 arc-sec rms, 4 rad/s²"),
])
def test_a_sentences_units_read_as_the_manual_prints_them(ascii_text, page_text):
    assert manual_units_in_text(ascii_text) == page_text


@pytest.mark.parametrize("text", ["N most", "kg·m² already", "DEG 5 degrees", "the degree"])
def test_words_that_are_not_units_stay(text):
    assert manual_units_in_text(text) == text
