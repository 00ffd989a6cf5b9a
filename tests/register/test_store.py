"""The register's questions: an axis's history, snapshot differences (also against a twin axis),
which axes have a parameter value, what is still open; and refusals that name what is wrong."""

from __future__ import annotations

import json
import sqlite3

import pytest

from fha_studio.logic.register import Register, RegisterError, default_register_path, utc_stamp
from fha_studio.logic.register.schema import SCHEMA_VERSION
from fha_studio.logic.session_log import WriteRecord

M = "Line 3 positioner"
DELIVERY = [
    ("system", 8, "rotary_direction", 0),
    ("tune", 0, "speed_loop_gain", 60),
    ("tune", 2, "position_loop_gain", 40),
]


def test_a_new_register_is_wal_at_the_current_version(register_file):
    register = register_file
    assert register.version == SCHEMA_VERSION
    assert register.journal_mode == "wal"
    assert register.integrity_check() == "ok"


def test_default_file_is_in_the_user_data_directory_or_the_sites_choice(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert default_register_path() == tmp_path / "xdg" / "FHA Studio" / "fha-studio" / "register.sqlite"
    with Register() as reg:  # created where the GUI's Qt AppDataLocation is, on first use
        assert reg.path.is_file() and reg.path == default_register_path()
    monkeypatch.setenv("FHA_STUDIO_REGISTER", str(tmp_path / "share" / "plant.sqlite"))
    assert default_register_path() == tmp_path / "share" / "plant.sqlite"


def test_machines_and_axes_are_found_by_name(line3):
    assert [m.name for m in line3.machines()] == [M]
    assert [a.name for a in line3.axes(M)] == ["table", "table twin", "tilt"]
    tilt = line3.axis(f"{M}/tilt")
    assert (tilt.actuator_code, tilt.port_url, tilt.load_inertia_kgm2) == (
        "FHA-32C-100-S248-B-L",
        "/dev/ttyUSB2",
        4.0,
    )
    assert line3.axis("tilt") == tilt  # a name only one machine has
    line3.add_machine("Robot wrist")
    line3.add_axis("Robot wrist", "tilt", "FHA-17C-50-US250")
    with pytest.raises(RegisterError, match="several machines have an axis called 'tilt'"):
        line3.axis("tilt")
    with pytest.raises(
        RegisterError,
        match=r"machine 'Line 3 positioner' has no axis 'roll' \(axes: table, table twin, tilt\)",
    ):
        line3.axis(f"{M}/roll")
    with pytest.raises(RegisterError, match="already has an axis called 'table'"):
        line3.add_axis(M, "table")
    with pytest.raises(RegisterError, match="already a machine called"):
        line3.add_machine(M)
    with pytest.raises(RegisterError, match="'/' separates machine and axis"):
        line3.add_machine("A/B")
    with pytest.raises(RegisterError, match="load inertia -1"):
        line3.add_axis(M, "roll", load_inertia_kgm2=-1)
    for value in (float("nan"), float("inf")):
        with pytest.raises(RegisterError, match="load inertia"):
            line3.add_axis(M, "roll", load_inertia_kgm2=value)
    with pytest.raises(RegisterError, match="axis 'roll': port /dev/ttyUSB2 is already axis 'tilt''s"):
        line3.add_axis(M, "roll", port_url="/dev/ttyUSB2")
    with pytest.raises(RegisterError, match="axis 'table': port /dev/ttyUSB2 is already axis 'tilt''s"):
        line3.update_axis(f"{M}/table", port_url="/dev/ttyUSB2")
    # another machine (on another computer, maybe) has ports of its own
    assert line3.add_axis("Robot wrist", "yaw", port_url="/dev/ttyUSB2").port_url == "/dev/ttyUSB2"


def test_history_of_an_axis_in_time_order(line3):
    table = f"{M}/table"
    first = line3.record_snapshot(table, DELIVERY, "link", who="ana", at_utc="2026-11-30T08:00:00Z")
    record = WriteRecord(
        time="2026-11-30T09:01:00+01:00",
        mode="system",
        number=8,
        key="rotary_direction",
        name="Rotary direction",
        old=0,
        new=1,
        read_back=1,
        verified=True,
    )
    line3.record_write(
        table,
        record.mode,
        record.number,
        record.key,
        record.new,
        record.old,
        record.read_back,
        record.verified,
        who="ana",
        at_utc=record.time,
    )
    line3.record_alarm(table, 20, "Deviation counter overflow", who="ana", at_utc="2026-11-30T08:30:00Z")
    line3.update_axis(table, who="ben", actuator_code="FHA-25C-100-US250")
    history = line3.history(table)
    assert [e.at_utc for e in history] == sorted(e.at_utc for e in history)
    events = [e for e in history if e.kind != "axis"]  # the axis events are stamped now
    assert [e.kind for e in events] == ["snapshot", "write", "alarm"]  # 09:01+01:00 is 08:01 UTC
    assert events[0].ref == first and "3 values" in events[0].text and events[0].who == "ana"
    assert events[1].text == "parameter 8 Rotary direction: 0 → 1: FWD turns CCW (reversed), verified"
    assert events[1].at_utc == "2026-11-30T08:01:00.000000+00:00"
    axis_events = [e for e in history if e.kind == "axis"]
    assert axis_events[0].text.startswith("axis added: FHA-25C-50-US250") and axis_events[0].who == "ana"
    assert (
        axis_events[1].text == "actuator: FHA-25C-50-US250 → FHA-25C-100-US250"
        and axis_events[1].who == "ben"
    )
    later = [e.kind for e in line3.history(table, since="2026-11-30T08:15:00Z") if e.kind != "axis"]
    assert later == ["alarm"]
    assert line3.history(f"{M}/tilt")[0].text.startswith("axis added: FHA-32C-100-S248-B-L, on HA-655-2-200")


def test_diff_between_snapshots_and_against_the_twin(line3):
    a = line3.record_snapshot(f"{M}/table", DELIVERY, "link", at_utc="2026-11-30T08:00:00Z")
    changed = [("system", 8, "rotary_direction", 1), ("tune", 2, "position_loop_gain", 45)]
    b = line3.record_snapshot(f"{M}/table", changed, "front_panel", who="ana", at_utc="2026-11-30T09:00:00Z")
    diff = Register.diff(line3.parameter_set(a), line3.parameter_set(f"#{b}"))
    assert [(d.key, d.a, d.b) for d in diff] == [
        ("rotary_direction", 0, 1),
        ("speed_loop_gain", 60, None),  # the front-panel snapshot did not read it
        ("position_loop_gain", 40, 45),
    ]
    # the twin: latest known values of each axis, a verified write counting as known
    line3.record_snapshot(f"{M}/table twin", DELIVERY, "link", at_utc="2026-11-30T08:00:00Z")
    line3.record_write(
        f"{M}/table twin", "tune", 0, "speed_loop_gain", 75, 60, 75, True, at_utc="2026-11-30T10:00:00Z"
    )
    line3.record_write(
        f"{M}/table twin", "tune", 2, "position_loop_gain", 99, 40, 40, False, error="read-back 40"
    )
    twin = Register.diff(line3.parameter_set(f"{M}/table"), line3.parameter_set(f"{M}/table twin"))
    assert {d.key: (d.a, d.b) for d in twin} == {
        "rotary_direction": (1, 0),
        "position_loop_gain": (45, 40),  # the unverified write does not count
        "speed_loop_gain": (60, 75),  # the table's 60 comes from the older snapshot
    }
    assert Register.diff(line3.parameter_set(a), line3.parameter_set(a)) == []
    with pytest.raises(RegisterError, match="no parameter snapshot number 99"):
        line3.parameter_set("99")


def test_find_axes_with_a_parameter_value(line3):
    for name in ("table", "table twin", "tilt"):
        line3.record_snapshot(f"{M}/{name}", DELIVERY, "link", at_utc="2026-11-30T08:00:00Z")
    line3.record_write(
        f"{M}/tilt", "system", 8, "rotary_direction", 1, 0, 1, True, at_utc="2026-11-30T09:00:00Z"
    )
    reversed_axes = line3.find("rotary_direction", 1)
    assert [f.axis.name for f in reversed_axes] == ["tilt"]
    assert reversed_axes[0].value.source == "write"
    # a later snapshot read back the delivery value: the axis is no longer reversed
    line3.record_snapshot(
        f"{M}/tilt", [("system", 8, "rotary_direction", 0)], "link", at_utc="2026-11-30T10:00:00Z"
    )
    assert line3.find("rotary_direction", 1) == []
    assert [f.axis.name for f in line3.find("rotary_direction")] == ["table", "table twin", "tilt"]
    assert "rotary_direction" in line3.known_keys()


def test_open_checks_and_unsigned_reports(line3, tmp_path):
    from fha_studio.logic.procedures.session import CheckRecord

    def record(step, passed, at):
        return CheckRecord(
            "wiring", step, "confirm", "1-14", f"check {step}", passed, "yes", "", passed, "ana", at
        )

    table = f"{M}/table"
    line3.record_procedure_status(table, "wiring", "Wiring", "completed", "1-14")
    line3.record_procedure_status(table, "installation", "Installation", "paused", "3-3")
    assert (
        line3.record_checks(
            table, [record("u", False, "2026-11-30T08:00:00Z"), record("v", False, "2026-11-30T08:01:00Z")]
        )
        == 2
    )
    assert (
        line3.record_checks(
            table, [record("u", True, "2026-11-30T08:05:00Z"), record("u", True, "2026-11-30T08:05:00Z")]
        )
        == 1
    )
    report = tmp_path / "table.html"
    report.write_text("<html>report</html>")
    line3.record_report(report, axis=table, open_warnings=1)
    items = {(i.axis.name, i.kind, i.text) for i in line3.open_items(M)}
    assert ("table", "check", "Installation (3-3): paused") in items
    assert ("table", "check", "Wiring: check v (1-14): failed, not checked again") in items
    assert not any("wiring / u" in text for _, _, text in items)  # checked again, passed
    assert ("table", "report", f"report {report.resolve()} is not signed") in items
    assert ("tilt", "check", "no procedure recorded yet") in items
    assert ("tilt", "report", "no commissioning report") in items
    assert line3.check_counts(table) == (1, 1)
    line3.record_report(report, axis=table, signed_by="ana", signed_utc=utc_stamp())
    assert not any(i.kind == "report" and i.axis.name == "table" for i in line3.open_items(M))


def test_report_keeps_the_files_hash(line3, tmp_path):
    report = tmp_path / "r.html"
    report.write_text("signed content")
    line3.record_report(report, axis=f"{M}/table", signed_by="ana")
    import hashlib

    assert line3.latest_report(f"{M}/table")["sha256"] == hashlib.sha256(b"signed content").hexdigest()
    with pytest.raises(FileNotFoundError):
        line3.record_report(tmp_path / "missing.html", axis=f"{M}/table")


def test_export_holds_everything_as_json(line3, tmp_path):
    line3.record_snapshot(f"{M}/table", DELIVERY, "link", who="ana")
    rec = tmp_path / "move.csv"
    rec.write_text("# fha-recording/1\n")
    line3.record_recording(f"{M}/table", rec, "move +90°", who="ana")
    line3.record_model_check(f"{M}/table", "Coulomb friction 11.9 ± 0.1 N m", recording_file=rec, who="ana")
    data = json.loads(json.dumps(line3.export(M)))
    axes = data["machines"][0]["axes"]
    assert [a["name"] for a in axes] == ["table", "table twin", "tilt"]
    assert axes[0]["current_values"]["rotary_direction"]["value"] == 0
    assert [e["kind"] for e in axes[0]["history"]] == ["axis", "snapshot", "recording", "model_check"]


def test_refusals_name_what_is_wrong(register, tmp_path):
    register.add_machine("m")
    register.add_axis("m", "a")
    with pytest.raises(RegisterError, match="source 'panel' is not one of link, front_panel, file"):
        register.record_snapshot("m/a", DELIVERY, "panel")
    with pytest.raises(RegisterError, match=r"rotary_direction\): value '1' is not a wire integer"):
        register.record_snapshot("m/a", [("system", 8, "rotary_direction", "1")], "link")
    with pytest.raises(RegisterError, match="'yesterday' is not a time"):
        register.record_alarm("m/a", 20, at_utc="yesterday")
    assert register.snapshots("m/a") == []  # nothing half-written
    garbage = tmp_path / "garbage.sqlite"
    garbage.write_bytes(b"this is not a database" * 100)
    with pytest.raises(RegisterError, match=r"garbage\.sqlite is not a register \(not an SQLite database"):
        Register(garbage)
    with pytest.raises(RegisterError, match="is a directory"):
        Register(tmp_path)


def test_a_register_from_a_newer_program_is_refused_unchanged(tmp_path):
    path = tmp_path / "new.sqlite"
    with Register(path):
        pass
    db = sqlite3.connect(path)
    db.execute(f"PRAGMA user_version = {SCHEMA_VERSION + 1}")
    db.commit()
    db.close()
    with pytest.raises(RegisterError, match=f"newer FHA Studio \\(schema {SCHEMA_VERSION + 1}"):
        Register(path)
