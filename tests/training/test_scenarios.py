"""Training scenarios: the shipped files load, a wrong file is one line naming file, line and
field, and the score sheet counts evidence, order and unsafe acts."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from fha_studio.hardware.protocol import Command, Status
from fha_studio.hardware.sim.journal import JournalEntry
from fha_studio.logic.procedures.session import CheckRecord, ProcedureSession, utc_now
from fha_studio.logic.training.scenario import ScenarioError, list_scenarios, load_scenario, scenarios_dir
from fha_studio.logic.training.score import TraineeRecord, score
from fha_studio.logic.training.sheet import TRAINING_MARK, render_sheet_html


def test_the_shipped_scenarios_load_from_a_first_day_to_a_two_fault_hunt():
    scenarios = list_scenarios()
    assert len(scenarios) >= 8
    assert scenarios[0].id == "first-day" and scenarios[0].level == "first day"
    assert any(len(s.faults) >= 2 for s in scenarios)
    kinds = {f.kind for s in scenarios for f in s.faults}
    assert kinds >= {
        "rotary_direction",
        "motor_wiring",
        "encoder_wiring",
        "brake_supply",
        "sensor_dog",
        "position_error_allowance",
        "battery",
        "mechanical_effect",
        "documented_profile",
    }


def test_the_briefing_never_names_a_hidden_fault():
    for s in list_scenarios():
        for f in s.faults:
            assert f.title.lower() not in s.briefing.lower(), (s.id, f.id)


GOOD = (scenarios_dir() / "error-allowance.toml").read_text()


def _write(tmp_path: Path, text: str, name: str = "error-allowance") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "change, expected",
    [
        (
            ('kind = "position_error_allowance"', 'kind = "gremlins"'),
            r":24: \[\[fault\]\] allowance: kind 'gremlins' is not one of rotary_direction, ",
        ),
        (
            ('sim = { preset = "system.6=1" }', 'sim = { wiring = "motor_open" }'),
            r":\d+: \[\[fault\]\] allowance, sim: a position_error_allowance fault sets preset "
            r"\(got wiring\)",
        ),
        (('level = "intermediate"', 'level = "expert"'), r":\d+: \[scenario\]: level 'expert' is not one of"),
        (
            (
                '{ kind = "parameter_written", item = "system.6", minimum = 100 }',
                '{ kind = "parameter_written", item = "system6" }',
            ),
            r"found_by 1: item 'system6' must be MODE.NUMBER",
        ),
        (
            ("time_guide_min = 25", "time_guide_min = 0"),
            r":\d+: \[scenario\]: time_guide_min 0 must be a number 1 ... 600",
        ),
        (
            ("time_guide_min = 25", 'time_guide_min = 25\ncolour = "red"'),
            r"\[scenario\]: unknown field colour; allowed: id, ",
        ),
        (
            ('sim = { preset = "system.6=1" }', 'sim = { preset = "system.6=99999" }'),
            r"preset system.6=99999",
        ),
    ],
)
def test_a_wrong_scenario_is_one_line_naming_file_line_and_field(tmp_path, change, expected):
    old, new = change
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(ScenarioError, match=expected) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))


def test_the_id_must_be_the_file_name(tmp_path):
    with pytest.raises(
        ScenarioError, match=r":\d+: \[scenario\]: id 'error-allowance' must equal the file name \(other\)"
    ):
        load_scenario(_write(tmp_path, GOOD, name="other"))


def _entry(at_s: float, command: str, value: int = 0, **state) -> JournalEntry:
    fields = {
        "terminal": "q",
        "item": None,
        "servo_on": False,
        "brake_holding": False,
        "blocked_fwd": False,
        "blocked_rev": False,
        "alarm_before": 0,
        "alarm_after": 0,
    }
    fields.update(state)
    fields["terminal"] = Status(fields["terminal"])
    return JournalEntry(at_s=at_s, command=Command(command), value=value, **fields)


def test_score_fault_found_and_missed_steps_in_and_out_of_order_and_unsafe_acts():
    hunt = load_scenario(scenarios_dir() / "fault-hunt.toml")
    t0 = time.time() - 600
    journal = [
        _entry(t0 + 10, "JOG", 500, servo_on=True, brake_holding=True),  # the brake holds: unsafe
        _entry(t0 + 10.05, "JOG", 500, servo_on=True, brake_holding=True),  # the same held jog
        _entry(t0 + 20, "PRD", item=("system", 6)),
        _entry(t0 + 30, "PWR", 500, item=("system", 6), servo_on=True, terminal="s"),  # unsafe, refused
        _entry(t0 + 40, "PWR", 500, item=("system", 6)),
        _entry(t0 + 50, "AHS"),
    ]
    record = TraineeRecord(
        started_s=t0, ended_s=t0 + 300, journal=journal, findings="P6 was wrong", trainee="Ann"
    )
    sheet = score(hunt, record)
    found = {r.fault.id: r.found for r in sheet.faults}
    assert found == {"brake-supply": False, "allowance": True}
    assert "wrote parameter item 6 = 500" in sheet.faults[1].evidence[0].text
    in_order = score(
        hunt,
        TraineeRecord(
            started_s=t0,
            ended_s=t0 + 300,
            journal=[
                _entry(t0 + 40, "PWR", 500, item=("system", 6)),
                _entry(t0 + 50, "JOG", 100, servo_on=True),
            ],
        ),
    )
    assert [s.in_order for s in in_order.steps] == [False, False, False]  # the wiring was never checked
    steps = {s.step.id: s for s in sheet.steps}
    assert steps["wiring"].done_at_s is None and not steps["wiring"].in_order
    assert steps["parameters"].done_at_s == pytest.approx(t0 + 40)
    assert not steps["parameters"].in_order and "Wiring and brake checked" in steps["parameters"].note
    assert steps["jog"].done_at_s == pytest.approx(t0 + 10) and not steps["jog"].in_order
    unsafe = {a.what: a.times for a in sheet.unsafe}
    assert unsafe == {"Moved the axis with the brake applied": 1, "Wrote a parameter with the servo on": 1}
    assert sheet.within_time_guide and sheet.time_taken_s == pytest.approx(300)
    html = render_sheet_html(sheet)
    assert TRAINING_MARK in html and "missed" in html and "found" in html and "Ann" in html


def test_score_counts_recorded_procedure_checks():
    first = load_scenario(scenarios_dir() / "first-day.toml")
    session = ProcedureSession(actuator_code=first.actuator)
    run = session.run("rotary-direction")
    run.records.append(
        CheckRecord(
            "rotary-direction",
            "seen-direction",
            "choose",
            "1-10",
            "Which way?",
            "CCW",
            "CW",
            "",
            False,
            "Ann",
            utc_now(),
        )
    )
    t = time.time()
    sheet = score(first, TraineeRecord(started_s=t - 60, ended_s=t + 1, session=session))
    assert sheet.faults[0].found
    assert "CCW" in sheet.faults[0].evidence[0].text


def test_a_scenario_name_too_long_for_a_file_is_no_scenario():
    from fha_studio.logic.training.scenario import ScenarioError, find_scenario

    with pytest.raises(ScenarioError) as err:
        find_scenario("n" * 10_000)
    assert str(err.value).startswith("no training scenario 'nnnn")
    assert "(10000 characters)" in str(err.value) and "\n" not in str(err.value)
