"""Times past what the register holds are refused in one line (not OverflowError)."""

from __future__ import annotations

import pytest

from fha_studio.logic.register import RegisterError, utc_stamp


@pytest.mark.parametrize("text", ["9999-12-31T23:59:59-05:00", "9999-12-31T23:00:00-01:00"])
def test_a_time_past_9999_utc_is_refused(text):
    with pytest.raises(RegisterError, match="is past the last time the register holds"):
        utc_stamp(text)


def test_a_session_created_past_9999_is_refused_on_import(register, tmp_path):
    from fha_studio.logic.register import import_session_file

    path = tmp_path / "s.json"
    path.write_text('{"format": "fha-session/1", "actuator_code": "FHA-25C-50-US250", '
                    '"created_utc": "9999-12-31T23:59:59-05:00", '
                    '"parameters": {"values": {"rotary_direction": 1}}}')
    with pytest.raises(RegisterError, match="is past the last time the register holds"):
        import_session_file(register, path, "Press 7", "feed")
    assert register.machines() == []  # nothing half-written
