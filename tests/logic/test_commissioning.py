"""The commissioning state of one axis: plain Python, listeners, nothing half-applied."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from fha_studio.catalog import ModelCodeError
from fha_studio.logic.commissioning import (
    BackupRequired,
    Change,
    CommissioningState,
    driver_family,
    driver_supply_voltage_v,
)
from fha_studio.logic.session_log import SessionLog, WriteRecord


def heard(state: CommissioningState) -> list[Change]:
    changes: list[Change] = []
    state.subscribe(changes.append)
    return changes


def write_record(mode="system", number=8, new=1, read_back=1, verified=True) -> WriteRecord:
    return WriteRecord(SessionLog.now(), mode, number, "rotary_direction", "Rotary direction", 0, new,
                       read_back, verified)


def test_the_actuator_is_parsed_by_the_catalogue_and_derives_ratio_resolution_and_supply():
    state = CommissioningState()
    assert state.actuator is None and state.ratio is None and state.supply_voltage_v == 200
    state.set_actuator(" fha-32c-100-s248 ")
    assert state.actuator_code == "FHA-32C-100-S248"
    assert state.ratio == 100 and state.model_code.encoder == "absolute"
    assert state.output_resolution_ppr == state.actuator.output_resolution_ppr
    state.set_actuator("FHA-25C-50-US250-A")
    assert state.supply_voltage_v == 100  # option A: AC100V (4-1)


def test_an_invalid_model_code_changes_nothing_and_says_what_is_wrong():
    state = CommissioningState("FHA-25C-50-US250")
    changes = heard(state)
    with pytest.raises(ModelCodeError, match="FHA-26C"):
        state.set_actuator("FHA-26C-50-US250")
    assert state.actuator_code == "FHA-25C-50-US250" and state.ratio == 50
    assert changes == []


def test_listeners_hear_each_change_once_and_not_a_repeat():
    state = CommissioningState()
    changes = heard(state)
    assert state.set_actuator("FHA-17C-50-US250")
    assert not state.set_actuator("fha-17c-50-us250")
    state.acknowledge_actuator()
    state.set_load_inertia(0.25)
    state.set_load_inertia(0.25)
    state.set_driver("HA-655-2-200", "FHA-17C-50-US250")
    state.set_driver("ha-655-2-200", "fha-17c-50-us250")
    assert changes == [Change.ACTUATOR, Change.ACTUATOR, Change.LOAD_INERTIA, Change.DRIVER, Change.ACTUATOR]
    assert not state.actuator_acknowledged  # acknowledged for no driver, not for this one
    state.acknowledge_actuator()
    state.set_driver("HA-655-2-200", "FHA-17C-50-US250")  # the same drive again: still acknowledged
    assert state.actuator_acknowledged


def test_unsubscribed_listeners_hear_nothing_and_a_failing_listener_does_not_silence_the_others():
    state = CommissioningState()
    changes: list[Change] = []
    unsubscribe = state.subscribe(changes.append)

    def broken(change: Change) -> None:
        raise RuntimeError("listener broke")

    state.subscribe(broken)
    later = heard(state)
    with pytest.raises(RuntimeError, match="listener broke"):
        state.set_load_inertia(1.0)
    assert changes == [Change.LOAD_INERTIA] and later == [Change.LOAD_INERTIA]
    assert state.load_inertia_kgm2 == 1.0
    unsubscribe()
    unsubscribe()  # twice is harmless
    with pytest.raises(RuntimeError):
        state.set_load_inertia(2.0)
    assert changes == [Change.LOAD_INERTIA]


@pytest.mark.parametrize("bad", [-0.1, math.nan, math.inf])
def test_a_load_inertia_that_is_not_a_value_at_least_zero_is_refused_whole(bad):
    state = CommissioningState(load_inertia_kgm2=0.5)
    with pytest.raises(ValueError, match="load inertia"):
        state.set_load_inertia(bad)
    assert state.load_inertia_kgm2 == 0.5


def test_supply_voltage_comes_from_the_actuator_else_the_driver_type_line():
    state = CommissioningState(driver_model="HA-655-4-100")
    assert state.supply_voltage_v == 100 and state.driver == "HA-655"
    state.set_actuator("FHA-25C-50-US250")
    assert state.supply_voltage_v == 200  # the actuator's label decides; the pairing check warns
    assert driver_family("ha-675-4-200") == "HA-675" and driver_family("") == "HA-655"
    assert driver_supply_voltage_v("HA-655-2-200") == 200 and driver_supply_voltage_v("") is None


def test_values_read_and_entered_from_the_front_panel_are_kept_apart():
    state = CommissioningState()
    changes = heard(state)
    state.record_read({("system", 8): 0})
    state.record_read({("system", 8): 0})  # the same again: nothing new
    entry = state.enter_front_panel("system", 9, 3, "A. Tech", time="2026-11-30T04:00:00+00:00")
    assert changes == [Change.DRIVE_VALUES, Change.FRONT_PANEL]
    assert state.front_panel[("system", 9)] == entry and entry.who == "A. Tech"
    assert state.value_of("system", 8) == 0 and state.value_of("system", 9) == 3
    assert state.value_of("tune", 1) is None
    with pytest.raises(ValueError, match="who"):
        state.enter_front_panel("system", 10, 1, "  ")
    with pytest.raises(TypeError):
        state.drive_values[("system", 8)] = 5  # read-only: every change goes through the state
    state.forget_drive()
    assert state.drive_values == {} and ("system", 9) in state.front_panel
    state.remove_front_panel("system", 9)
    assert state.front_panel == {}


def test_writes_wait_for_a_backup_are_logged_and_a_new_drive_needs_its_own(tmp_path: Path):
    log = SessionLog(tmp_path / "session.jsonl")
    state = CommissioningState("FHA-25C-50-US250", write_log=log)
    assert state.needs_backup
    with pytest.raises(BackupRequired, match="rotary direction: back up"):
        state.require_backup("rotary direction")
    state.record_backup(tmp_path / "backup.toml")
    state.require_backup()
    changes = heard(state)
    state.record_write(write_record(new=1, read_back=1))
    state.record_write(write_record(number=9, new=2, read_back=None, verified=False))
    assert [r.number for r in state.writes] == [8, 9]
    assert state.drive_values == {("system", 8): 1}  # an unverified write is not taken as the value
    assert SessionLog.read(log.path).records == state.writes
    assert Change.WRITE_LOG in changes
    state.forget_drive()
    assert state.needs_backup and state.backup_path is None


def test_states_are_independent_objects_one_per_axis():
    a, b = CommissioningState("FHA-17C-50-US250"), CommissioningState("FHA-40C-160-S248")
    a.set_load_inertia(1.0)
    a.record_read({("system", 8): 1})
    assert b.load_inertia_kgm2 == 0.0 and b.drive_values == {} and b.ratio == 160
