"""Property tests of the register's inputs: sessions, machine files and register arguments of
random shape are taken or refused in one line; never a traceback, an exit of 128 or more, or a
write on a refusal (the register file is unchanged when a command refuses)."""

from __future__ import annotations

import json
import shutil

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fha_studio.logic.machine import MachineError, MachineProject
from fha_studio.logic.register import Register, RegisterError, import_session_file
from fha_studio.main import main

FUZZ = settings(max_examples=120, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])

scalars = (st.none() | st.booleans() | st.integers(-(2**70), 2**70)
           | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=30))
json_values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4)
                           | st.dictionaries(st.text(max_size=12), inner, max_size=4), max_leaves=20)
SESSION_KEYS = ["axis", "operator", "site", "created_utc", "driver", "signature",
                "notes", "plots", "sensor_angles_deg", "runs", "unknown"]
PARAMETER_VALUES = st.dictionaries(
    st.sampled_from(["rotary_direction", "in_position_range", "no_such_item", "speed_loop_gain"]),
    scalars | json_values, max_size=4)
sessions = st.fixed_dictionaries(
    {"format": st.just("fha-session/1"),
     "actuator_code": st.sampled_from(["FHA-25C-50-US250", "FHA-99Z", "", "fha-17c-50-us250"]) | scalars},
    optional={
        **{k: json_values for k in SESSION_KEYS},
        "parameters": st.fixed_dictionaries({}, optional={"values": PARAMETER_VALUES | json_values,
                                                          "read_utc": scalars, "file": scalars}),
    },
)
machine_axes = st.lists(
    st.fixed_dictionaries({"name": st.text(max_size=100) | scalars},
                          optional={"actuator_code": scalars, "port_url": st.text(max_size=400) | scalars,
                                    "load_inertia_kgm2": scalars, "notes": scalars, "bogus": scalars})
    | json_values, max_size=3)
machines = st.fixed_dictionaries(
    {"format": st.just("fha-machine/1"), "name": st.text(max_size=120) | scalars},
    optional={"site": scalars, "notes": scalars, "axes": machine_axes | json_values},
)


@pytest.fixture(scope="module")
def new_register(tmp_path_factory):
    """A new, empty register file, made once: each example takes a copy (a register's creation
    commits its schema step by step, each commit synced to the disk: 0.1 s under load)."""
    path = tmp_path_factory.mktemp("new") / "r.sqlite"
    Register(path).close()
    return path


@FUZZ
@given(data=sessions)
def test_a_session_of_any_shape_is_imported_or_refused_leaving_nothing(tmp_path, new_register, data):
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    shutil.copyfile(new_register, tmp_path / "r.sqlite")
    with Register(tmp_path / "r.sqlite") as register:
        before = register.export()["machines"]
        try:
            import_session_file(register, path, "Press 7", "feed")
        except RegisterError as exc:
            assert "\n" not in str(exc)
            assert register.export()["machines"] == before  # nothing half-written
    (tmp_path / "r.sqlite").unlink()


@FUZZ
@given(data=machines)
def test_a_machine_file_of_any_shape_is_read_or_refused_in_one_line(tmp_path, data):
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    try:
        project = MachineProject.load(path)
    except MachineError as exc:
        assert "\n" not in str(exc) and str(path) in str(exc)
        return
    for axis in project:
        assert len(axis.name) <= 80 and axis.name.isprintable()


ARG = st.text(max_size=40) | st.sampled_from(
    ["1", "²", "1_5", "١", "9" * 30, "9999-12-31T23:59:59-05:00", "Press 7", "Press 7/feed", "-x", "--json"])
ACTIONS = ["machines", "axes", "history", "diff", "find", "open", "export", "check", "add-machine",
           "add-axis"]


@pytest.fixture(scope="module")
def filled(tmp_path_factory):
    path = tmp_path_factory.mktemp("reg") / "r.sqlite"
    with Register(path) as register:
        register.add_machine("Press 7")
        register.add_axis("Press 7", "feed", "FHA-25C-50-US250", port_url="/dev/ttyUSB0")
        register.record_snapshot("Press 7/feed", [("system", 8, "rotary_direction", 1)], "link")
    return path


@FUZZ
@given(action=st.sampled_from(ACTIONS), args=st.lists(ARG, max_size=3))
def test_register_arguments_of_any_shape_end_in_an_answer_or_one_line(filled, capsys, action, args):
    before = filled.read_bytes()
    try:
        code = main(["register", "--register", str(filled), action, *args])
    except SystemExit as exc:  # argparse refuses
        code = exc.code
    assert isinstance(code, int) and 0 <= code < 128
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code == 2:
        assert err.count("\n") == 1
        if action in ("add-machine", "add-axis"):
            assert filled.read_bytes() == before  # a refusal writes nothing
