"""``sim://...?catalogue_friction=1``: the simulated axis has the friction the catalogue gives (TF =
Kt x Im - TM at maximum speed, FHA-C manual 2-4-4), so it stops like a real axis after an alarm and
a steady jog draws the current that friction needs. A bare ``sim://`` stays frictionless.

Seen through the ordinary client over ``sim://...?paced=0&stepped=1``: the drive's time advances
only by ``advance``, so a loaded machine changes no figure here. The expected figures come from
the manual's numbers for the FHA-25C-50 (its 2-4-4 example: JA = 0.81 kg m^2, TM = 150 N m,
KT = 22 N m/A, Im = 7.3 A, so TF = 10.6 N m; maximum speed 90 r/min, 1-4) and the split of TF the
physics assumes (half Coulomb, half viscous reaching TF at maximum speed)."""

from __future__ import annotations

import math

import pytest

from fha_studio.cli import build_parser
from fha_studio.cli.sim import sim_config
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.sim import SimDrive
from fha_studio.hardware.sim.options import SimConfigError, config_from_url
from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics.model import COULOMB_SHARE_OF_TF
from fha_studio.recording import read_recording
from tests.sim.conftest import advance
from tests.support.recorded_moves import record_moves

ACTUATOR = "FHA-25C-50-US250"
JA_KGM2, KT_NM_PER_A = 0.81, 22.0
TF_NM = KT_NM_PER_A * 7.3 - 150.0  # 10.6 N m (2-4-4, example 1)
MAX_RPM = 90.0
MAX_RAD_S = MAX_RPM * 2 * math.pi / 60
COULOMB_NM = COULOMB_SHARE_OF_TF * TF_NM
VISCOUS_NM_S_PER_RAD = (1 - COULOMB_SHARE_OF_TF) * TF_NM / MAX_RAD_S
JOG_REPEAT_S = 0.04  # a held jog button repeats JOG inside the drive's 100 ms watchdog
LOOK_S = 0.02  # how often the test reads the speed while the axis coasts


def _open(query: str) -> DriveClient:
    return DriveClient.open(f"sim://{ACTUATOR}?paced=0&stepped=1&{query}")


def _jog(client: DriveClient, speed_rpm: float, seconds: float) -> None:
    held = 0.0
    while held < seconds - 1e-9:
        client.jog(speed_rpm)
        advance(client, JOG_REPEAT_S)
        held += JOG_REPEAT_S


def _speed_rpm(client: DriveClient) -> float:
    return client.read_monitor(MonitorItem.OUTPUT_SPEED) / 100.0


def _coast_after_alarm(client: DriveClient, longest_s: float) -> tuple[float, float]:
    """At full speed, an alarm (the motor de-energised): (drive seconds until the output stands
    still, or ``longest_s``; its speed then, r/min)."""
    client.servo(True)
    _jog(client, MAX_RPM, 1.0)
    assert _speed_rpm(client) == pytest.approx(MAX_RPM, abs=0.5)
    client.inject_alarm(60)
    assert client.alarm() == 60
    t = 0.0
    while t < longest_s - 1e-9 and _speed_rpm(client) != 0.0:
        advance(client, LOOK_S)
        t += LOOK_S
    return t, _speed_rpm(client)


def test_the_option_puts_the_catalogue_friction_under_the_explicit_effects():
    assert config_from_url(f"sim://{ACTUATOR}").catalogue_friction is False
    assert config_from_url(f"sim://{ACTUATOR}?catalogue_friction=1").catalogue_friction is True
    with SimDrive.from_url(f"sim://{ACTUATOR}?stepped=1") as bare:
        assert bare.model.effects.enabled() == []  # a bare sim:// is frictionless, as ever
    with SimDrive.from_url(f"sim://{ACTUATOR}?stepped=1&catalogue_friction=1") as drive:
        effects = drive.model.effects
        assert effects.enabled() == ["coulomb_friction", "viscous_friction"]  # not the gear's compliance
        assert effects.coulomb_friction.torque_nm == pytest.approx(COULOMB_NM)
        assert effects.viscous_friction.coefficient_nm_s_per_rad == pytest.approx(VISCOUS_NM_S_PER_RAD)
    # an effect given explicitly wins over the catalogue's of the same id; the rest stays
    url = (f"sim://{ACTUATOR}?stepped=1&catalogue_friction=1"
           "&effects=coulomb_friction:torque_nm=8;gravity_load:amplitude_nm=3")
    with SimDrive.from_url(url) as drive:
        effects = drive.model.effects
        assert effects.coulomb_friction.torque_nm == 8.0
        assert effects.viscous_friction.coefficient_nm_s_per_rad == pytest.approx(VISCOUS_NM_S_PER_RAD)
        assert effects.gravity_load.amplitude_nm == 3.0
    with pytest.raises(SimConfigError, match="catalogue_friction: 'maybe' is not 1/0"):
        config_from_url(f"sim://{ACTUATOR}?catalogue_friction=maybe")


def test_fha_studio_sim_takes_the_option_as_a_flag():
    parse = build_parser().parse_args
    assert sim_config(parse(["sim", "--pty", "--catalogue-friction"])).catalogue_friction is True
    assert sim_config(parse(["sim", "--pty"])).catalogue_friction is False


@pytest.mark.parametrize("load_kgm2", [0.0, 1.5])
def test_after_an_alarm_at_speed_the_axis_comes_to_rest_as_its_friction_says(load_kgm2):
    """Coasting from w0 against Coulomb Fc and viscous b: J dw/dt = -(Fc + b w), at rest after
    J / b x ln(1 + b w0 / Fc): 1.0 s unloaded, 2.8 s with the manual's 1.5 kg m^2 load."""
    j = JA_KGM2 + load_kgm2
    expected_s = j / VISCOUS_NM_S_PER_RAD * math.log(1 + VISCOUS_NM_S_PER_RAD * MAX_RAD_S / COULOMB_NM)
    client = _open(f"catalogue_friction=1&load_inertia={load_kgm2}")
    try:
        rest_s, speed = _coast_after_alarm(client, longest_s=10.0)
    finally:
        client.close()
    assert speed == 0.0
    assert rest_s == pytest.approx(expected_s, abs=2 * LOOK_S)


def test_without_the_option_the_axis_coasts_on():
    client = _open("load_inertia=1.5")
    try:
        _, speed = _coast_after_alarm(client, longest_s=5.0)
    finally:
        client.close()
    assert speed == pytest.approx(MAX_RPM, abs=0.5)  # nothing slows a frictionless axis


@pytest.mark.parametrize(("speed_rpm", "friction_nm"), [
    (MAX_RPM, TF_NM),  # at maximum speed the friction is TF itself (2-4-4)
    (MAX_RPM / 3, COULOMB_NM + VISCOUS_NM_S_PER_RAD * MAX_RAD_S / 3),
], ids=["maximum speed", "a third of it"])
def test_a_steady_jog_draws_the_current_of_the_friction(speed_rpm, friction_nm):
    """Monitor 112 (the 10 ms mean current) during a steady jog: friction / KT with the option,
    nothing without. Within 2 %: the current's noise from whole encoder pulses is far smaller."""
    currents = {}
    for option in ("catalogue_friction=1", "catalogue_friction=0"):
        client = _open(f"{option}&load_inertia=1.5")
        try:
            client.servo(True)
            _jog(client, speed_rpm, 1.0)  # accelerated, settled
            samples = []
            for _ in range(10):
                client.jog(speed_rpm)
                advance(client, JOG_REPEAT_S)
                samples.append(client.read_monitor(MonitorItem.MOTOR_CURRENT_MEAN) / 1000.0)
            currents[option] = samples
        finally:
            client.close()
    expected_a = friction_nm / KT_NM_PER_A
    assert all(a == pytest.approx(expected_a, rel=0.02) for a in currents["catalogue_friction=1"])
    assert all(abs(a) < 0.02 * expected_a for a in currents["catalogue_friction=0"])


def test_the_model_check_names_the_friction_of_a_recording_of_such_a_drive(tmp_path):
    """A recording of moves at several speeds on the drive with the catalogue's friction: the model
    check finds Coulomb and viscous friction of the catalogue's size. Over the recorded speeds it
    may trade a little of one for the other (both within 10 %); their sum at maximum speed, TF,
    within 5 %."""
    path = tmp_path / "friction.csv"
    with SimDrive(ACTUATOR, load_inertia_kgm2=1.5, catalogue_friction=True, stepped=True) as drive:
        record_moves(drive, path, [(200, 80), (-120, 20), (300, 60), (-250, 40), (90, 10), (-330, 90)])
    result = run_modelcheck(read_recording(path), resimulate=False)
    found = {e.id: e.params for e in result.effects}
    assert set(found) == {"coulomb_friction", "viscous_friction"}, result.summary_lines()
    coulomb = found["coulomb_friction"]["torque_nm"]
    viscous = found["viscous_friction"]["coefficient_nm_s_per_rad"]
    assert coulomb == pytest.approx(COULOMB_NM, rel=0.10)
    assert viscous == pytest.approx(VISCOUS_NM_S_PER_RAD, rel=0.10)
    assert coulomb + viscous * MAX_RAD_S == pytest.approx(TF_NM, rel=0.05)


def test_a_drive_in_words_says_whether_it_has_the_catalogues_friction():
    from fha_studio.hardware.sim.options import drive_words

    assert drive_words("sim://FHA-25C-50-US250?catalogue_friction=1&eeprom=/tmp/x") == (
        "embedded simulated drive")
    assert drive_words("sim://FHA-25C-50-US250?catalogue_friction=1", detail=True) == (
        "embedded simulated drive FHA-25C-50-US250, with the catalogue's friction (TF, 2-4-4)")
    assert drive_words("sim://FHA-17C-100-US200", detail=True).endswith(
        "without the catalogue's friction (TF, 2-4-4)")
    assert drive_words("sim://FHA-25C-50-US250 (training)", detail=True) == (
        "embedded simulated drive FHA-25C-50-US250 (training)")
    assert drive_words("/dev/ttyUSB0", detail=True) == "/dev/ttyUSB0"
