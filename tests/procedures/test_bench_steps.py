"""A move seen on the bench (CN2: the controller's command pulses and the encoder outputs) answers
the procedure steps marked ``bench``: the 1-10 check's FWD move and which way the flange turned
(from the encoder outputs and parameter 8), and the wiring's encoder phases; the same checks the
DGR checks page records (logic/bench/checks.py)."""

from __future__ import annotations

import numpy as np

from fha_studio.logic.bench.checks import bench_checks
from fha_studio.logic.procedures import Observation, ProcedureRun, ProcedureSession
from fha_studio.logic.procedures.bench_steps import answer_from_bench, bench_kind, parameter_8_of_run
from fha_studio.logic.procedures.definitions import load_procedure

T = np.arange(0, 1.0, 1e-3)
CMD = np.clip((T - 0.1) / 0.3, 0, 1) * 5000.0
SOURCE = "the bench instrument demo (encoder D0,D1, command D2,D3)"


def _steps(context):
    procedure = load_procedure("rotary-direction", context)
    run = ProcedureRun(ProcedureSession(actuator_code=context["actuator"]["model_code"]), procedure,
                       autosave=False)
    return procedure, run


def test_the_steps_that_a_bench_move_answers_are_marked_in_the_procedure_files(context):
    procedure, _run = _steps(context)
    kinds = {s.id: bench_kind(s.resolve(context, {"fwd_direction": "CW"})) for s in procedure.steps}
    assert kinds == {"fwd_direction": "", "parameter": "", "jog-fwd": "direction", "seen-direction": "flange"}
    wiring = load_procedure("wiring", context)
    assert bench_kind(wiring.step("encoder-phases").resolve(context, {})) == "encoder"


def test_a_fwd_move_answers_the_jog_and_with_parameter_8_which_way_the_flange_turned(context):
    procedure, run = _steps(context)
    run.submit("CW", who="A")
    run.submit(Observation(0, True, "entered by hand"), who="A")
    assert parameter_8_of_run(procedure, run.state) == 0
    checks = bench_checks(T, CMD, CMD, parameter_8=0, source=SOURCE)
    jog = answer_from_bench(run.current(), checks, 0)
    assert jog.value.passed and jog.value.value == "FWD (+5000 counts for +5000 commanded)"
    assert jog.value.detail.startswith("from CN2: a FWD command (+5000 counts) turned the axis FWD")
    run.submit(jog.value, who="A")
    seen = answer_from_bench(run.current(), checks, 0)
    assert seen.value == "CW" and seen.detail.startswith(
        "from the encoder outputs on the bench: a FWD command turned the axis FWD (+5000 counts), with "
        "parameter 8 = 0: FWD rotation, CW viewing the output flange (1-10), on the bench instrument demo")
    record = run.submit(seen.value, who="A", detail=seen.detail)
    assert record.passed and run.completed
    # parameter 8 = 1 (reversed): the same count is CCW at the flange, which the chosen CW fails
    assert answer_from_bench(procedure.step("seen-direction").resolve(context, {"fwd_direction": "CW"}),
                             checks, 1).value == "CCW"


def test_a_move_that_cannot_answer_says_why(context):
    procedure, _ = _steps(context)
    jog = procedure.step("jog-fwd").resolve(context, {})
    seen = procedure.step("seen-direction").resolve(context, {"fwd_direction": "CW"})
    rev = answer_from_bench(jog, bench_checks(T, -CMD, -CMD, source=SOURCE), 0)
    assert not rev.answers
    assert rev.detail.startswith("a REV command came (-5000 counts): this step wants a FWD")
    unknown = answer_from_bench(seen, bench_checks(T, CMD, CMD, source=SOURCE), None)
    assert not unknown.answers and "needs parameter 8: record it first" in unknown.detail
    nothing = answer_from_bench(jog, bench_checks(T, np.zeros(T.size), CMD, source=SOURCE), 0)
    assert not nothing.answers and "no command pulses came" in nothing.detail
    swapped = answer_from_bench(jog, bench_checks(T, CMD, -CMD, source=SOURCE), 0)
    assert swapped.value.passed is False and swapped.value.value.startswith("REV (-5000 counts")


def test_the_encoder_phases_from_a_bench_move(context):
    step = load_procedure("wiring", context).step("encoder-phases").resolve(context, {})
    good = answer_from_bench(step, bench_checks(T, CMD, CMD, source=SOURCE), None)
    assert good.value.passed and good.value.value == "+5000 counts for +5000 commanded"
    halved = answer_from_bench(step, bench_checks(T, CMD, CMD / 2, source=SOURCE), None)
    assert halved.value.passed is False and "electronic gear" in halved.value.detail
