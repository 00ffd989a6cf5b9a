"""Answering a procedure step on the Procedures page as a technician does (the GUI tests share it)."""

from __future__ import annotations

from typing import Any

from tests.procedures.walk import good_answer


def answer_by_hand(page: Any, step: Any) -> bool:
    """Click or type the good answer to ``step`` (confirm, measure, text, choose) on ``page``;
    False for a step the drive answers (a live check: the caller presses its button)."""
    if step.kind == "confirm":
        page.yes_button.click()
    elif step.kind in ("measure", "text"):
        page.value_edit.setText(str(good_answer(step)))
        page.value_button.click()
    elif step.kind == "choose":
        page.choice_combo.setCurrentText(str(good_answer(step)))
        page.choice_button.click()
    else:
        return False
    return True
