"""The model check of a recording without current: what the closed loop lets it see.

A bench capture of an HA-655 gives the command, the encoder position (and SPD-MON, IN-POS) but no
current. The disturbance then shows in the following error, through the loop that fought it: the
loop is identified from the recording (loopfit.py: the following error its linear model leaves,
Kp, FF, g = Kt Kv and Tv fitted), and the candidate effects are seen through it. The tune items'
units are not documented on the HA-655, so the loop comes from the recording and is compared with
the panel's values when the caller knows them, not taken from them; the loop found is also given as
the panel would show it (``physics.PanelGains``: the speed loop gain read on the actuator's own
inertia, as the simulated drive and tuning read it).

What cannot be identified this way, said in the report: a constant load torque and the part of
friction that differs by direction are held by the speed loop's integral (they leave no trace in
the following error); an inertia error trades off against the loop's gain scale g (J and g appear
only as g / J); viscous friction trades off against the speed loop's gain and the lag of the
drive's speed detection (a lag tau reads as viscous friction -g tau / Tv, which no recording of
command and position separates from a real one: on the simulated drive a viscous drag of 1 N m
s/rad came out as a 5 % larger Kv and no friction; a coast after an alarm shows it, coast.py);
every torque in N m rests on the declared inertia; a torque-constant error has no current to act
on. Without an encoder on the load, the gear's kinematic error, lost motion and wind-up are not
seen either: the motor's encoder sits before the gear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fha_studio.logic.modelcheck.axis import DeclaredAxis, ModelCheckError
from fha_studio.logic.modelcheck.candidates import TORQUE, TORQUE_CANDIDATES, ChannelContext
from fha_studio.logic.modelcheck.loopfit import LoopFit, LoopParams
from fha_studio.logic.modelcheck.signals import ARCSEC_PER_RAD, Signals, build_signals, window_for_bandwidth
from fha_studio.physics import AxisModel, PanelGains, ServoSettings
from fha_studio.recording import Recording

#: without a current the torque is only as good as the acceleration: a fixed analysis bandwidth,
#: well under the speed loop's and over what friction and gravity change at
ANALYSIS_BANDWIDTH_HZ = 25.0
#: effects a recording without a torque measurement cannot show (see the module text)
NOT_IDENTIFIABLE = (
    "inertia_error",
    "load_torque_offset",
    "asymmetric_friction",
    "torque_constant_error",
    "viscous_friction",
)
CANDIDATES_WITHOUT_CURRENT = tuple(c for c in TORQUE_CANDIDATES if c.id not in NOT_IDENTIFIABLE)


@dataclass(frozen=True)
class Loop:
    """The closed loop identified from a recording (and, when known, the panel's values)."""

    position_gain_per_s: float  # Kp
    feed_forward: float  # FF
    integral_time_s: float  # Tv
    torque_per_speed_error_nm_s_per_rad: float  # g = Kt Kv, resting on the declared inertia
    speed_gain_a_s_per_rad: float  # Kv = g / Kt
    panel: ServoSettings | None = None
    inertia_kgm2: float = 1.0  # the declared inertia g rests on
    explains: bool = True  # the loop model explains the following error (loopfit.LoopFit.explains)
    speed_lag_s: float = 0.0  # the lag of the speed the loop sees (the drive's speed detection)
    command_lead_s: float = 0.0  # the drive acts on the command this much earlier than recorded
    model: AxisModel | None = None  # the declared axis, to say the loop in the panel's units

    def servo(self, servo_rate_hz: float = 5000.0) -> ServoSettings:
        """The identified loop as servo settings, for the re-simulation: whole encoder pulses, their
        difference per period (half a period late) low-passed to the identified speed lag."""
        dt = 1.0 / servo_rate_hz
        rest = self.speed_lag_s - 0.5 * dt  # what the filter adds: (1 - alpha) / alpha periods
        filter_hz = 0.0 if rest <= 0 else -math.log(dt / (rest + dt)) / (2.0 * math.pi * dt)
        return ServoSettings(
            position_loop_gain_per_s=max(self.position_gain_per_s, 1e-3),
            speed_loop_gain_a_s_per_rad=max(self.speed_gain_a_s_per_rad, 1e-9),
            speed_loop_integral_time_s=self.integral_time_s,
            feed_forward_gain=min(max(self.feed_forward, 0.0), 1.0),
            quantised_feedback=True,  # a drive's loops see whole encoder pulses
            servo_rate_hz=servo_rate_hz,
            speed_filter_hz=filter_hz,
        )

    @property
    def plausible(self) -> bool:
        """A loop that can be: every parameter inside the range searched (one at its edge was not
        found, only pushed there) and the loop model explaining the following error."""
        p = LoopParams(
            self.position_gain_per_s,
            self.feed_forward,
            self.torque_per_speed_error_nm_s_per_rad,
            self.integral_time_s,
        )
        return self.explains and p.inside(self.inertia_kgm2)

    def lines(self) -> list[str]:
        if not self.plausible:
            return [
                "The closed loop is not pinned down by this recording (the fit gives Kp "
                f"{self.position_gain_per_s:.3g} 1/s, Tv {1000.0 * self.integral_time_s:.3g} ms, "
                f"feed-forward {self.feed_forward:.2f}, no loop a drive runs): record moves with clear "
                "accelerations that keep the current within its limit."
            ]
        text = (
            f"Closed loop identified from the recording: Kp {self.position_gain_per_s:.3g} 1/s, "
            f"Kv {self.speed_gain_a_s_per_rad:.3g} A s/rad "
            f"(Kt Kv {self.torque_per_speed_error_nm_s_per_rad:.3g} N m s/rad on the declared inertia), "
            f"Tv {1000.0 * self.integral_time_s:.3g} ms, "
            f"feed-forward {self.feed_forward:.2f}, the speed it sees {1000.0 * self.speed_lag_s:.2g} ms late"
        )
        if self.model is not None:
            found = PanelGains.of_settings(self.model, self.servo())
            text += (
                "; as the front panel would show it (tune 0 read on the actuator's own inertia): speed loop "
                f"gain {found.speed_loop_gain_hz:.3g} Hz, integral compensation "
                f"{found.speed_loop_integral_compensation_ms:.3g} ms, position loop gain "
                f"{found.position_loop_gain_per_s:.3g} 1/s, feed-forward {found.feed_forward_gain_pct:.0f} %"
            )
        if self.panel is None:
            return [text + " (no panel values given to compare)."]
        p = self.panel
        on_panel = "."
        if self.model is not None:
            panel_hz = PanelGains.of_settings(self.model, p).speed_loop_gain_hz
            on_panel = f" (speed loop gain {panel_hz:.4g} Hz on the panel)."

        def pct(found: float, panel: float) -> str:
            return f"{100.0 * (found / panel - 1.0):+.0f} %" if panel and math.isfinite(panel) else "n/a"

        return [
            text + ".",
            "  Against the panel's values read as docs/physics.md does (speed command = Kp x error, "
            f"current = Kv x (e + integral/Tv)): Kp {p.position_loop_gain_per_s:.3g} "
            f"({pct(self.position_gain_per_s, p.position_loop_gain_per_s)}), "
            f"Kv {p.speed_loop_gain_a_s_per_rad:.3g} "
            f"({pct(self.speed_gain_a_s_per_rad, p.speed_loop_gain_a_s_per_rad)}), "
            f"Tv {1000.0 * p.speed_loop_integral_time_s:.3g} ms "
            f"({pct(self.integral_time_s, p.speed_loop_integral_time_s)}), "
            f"feed-forward {p.feed_forward_gain:.2f}{on_panel}",
        ]


def closed_loop_signals(rec: Recording, axis: DeclaredAxis) -> Signals:
    """Step 1 without a current: position derivatives at ANALYSIS_BANDWIDTH_HZ (the torque is zero
    until the loop is identified)."""
    if rec.cmd_pos_deg is None:
        raise ModelCheckError(
            "the recording has neither a current nor a command (cmd_pos): without the command the "
            "closed loop cannot be read; record the command pulses with the encoder"
        )
    t = rec.t_s
    dt = float(np.median(np.diff(t)))
    window = window_for_bandwidth(ANALYSIS_BANDWIDTH_HZ, len(t), dt)
    try:
        return build_signals(
            t,
            np.radians(rec.pos_deg),
            np.zeros(len(t)),
            kt_nm_per_a=axis.kt_nm_per_a,
            inertia_kgm2=axis.nominal_inertia_kgm2,
            ratio=axis.ratio,
            load_pos_rad=None if rec.load_pos_deg is None else np.radians(rec.load_pos_deg),
            cmd_pos_rad=np.radians(rec.cmd_pos_deg),
            window=window,
        )
    except ValueError as exc:
        raise ModelCheckError(str(exc)) from None


#: breakaway fading speeds (rad/s) among the loop fit's proxies
PROXY_STRIBECK_SPEEDS_RAD_S = (0.03, 0.15)


def friction_proxies(ctx: ChannelContext, with_load: bool = True) -> np.ndarray:
    """Friction (Coulomb, breakaway) and gravity columns (analysis rate): the loop is fitted with
    them beside it, so that it is not bent to explain them (a missing one biases the loop's gain:
    on the simulated drive, breakaway left out made Kt Kv 26 % small). ``with_load``: False when
    the load's torque is measured (an output torque sensor): friction only."""
    by_id = {c.id: c for c in CANDIDATES_WITHOUT_CURRENT}
    columns = [by_id["coulomb_friction"].build(ctx, ())]
    columns += [by_id["stribeck_friction"].build(ctx, (v,)) for v in PROXY_STRIBECK_SPEEDS_RAD_S]
    if with_load:
        columns.append(by_id["gravity_load"].build(ctx, ()))
    return np.column_stack(columns)


#: the recording that would separate two effects when the torque is read through the loop (the
#: with-current tests ask for steady-speed levels, which the loop's integral hides here)
SEPARATING_WITHOUT_CURRENT: dict[frozenset[str], str] = {
    frozenset({"coulomb_friction", "stribeck_friction"}): (
        "record the current (or an output torque sensor) through slow constant-speed runs: without a "
        "torque measurement a friction's level at a steady speed is held by the loop's integral, and "
        "breakaway shows only in how the axis breaks loose; starts from standstill to several low "
        "speeds help"
    ),
}


def loop_of(fit: LoopFit, model: AxisModel, panel: ServoSettings | None, inertia_kgm2: float) -> Loop:
    """The loop to report from its fit, on the declared axis ``model``."""
    p = fit.params
    return Loop(
        position_gain_per_s=p.kp,
        feed_forward=p.ff,
        integral_time_s=p.tv,
        torque_per_speed_error_nm_s_per_rad=p.g,
        speed_gain_a_s_per_rad=p.g / model.torque_constant_nm_per_a,
        panel=panel,
        inertia_kgm2=inertia_kgm2,
        explains=fit.explains,
        speed_lag_s=p.lag,
        command_lead_s=p.lead,
        model=model,
    )


def not_identifiable_lines(
    axis: DeclaredAxis, sensor: bool = False, load_encoder: bool = True, coast: bool = False
) -> list[str]:
    """What a recording without current cannot show; ``sensor``: it has an output torque sensor,
    which measures the load's side (then only the gear is read through the loop); ``load_encoder``:
    it has the load's position (else the gear's own errors are not seen either); ``coast``: a coast
    after an alarm showed viscous friction (coast.py)."""
    viscous = (
        "viscous friction reads like the lag of the drive's speed detection (a lag makes the loop "
        "push as a drag would pull), so it trades off against the loop's gains"
        + (
            " (with the servo on: the coast after the alarm shows it, above)"
            if coast
            else "; a coast from speed after an alarm, with the ALARM line recorded, shows it"
        )
    )
    gear = (
        []
        if load_encoder
        else [
            "Without an encoder on the load the gear's kinematic error, lost motion and wind-up cannot be "
            "seen: the motor's encoder sits before the gear. Map an encoder on the output flange "
            "(bench import: --signal load_encoder_a=... --signal load_encoder_b=... --load-encoder-counts)."
        ]
    )
    if sensor:
        j_gear = axis.nominal_inertia_kgm2 - axis.model.load_inertia_kgm2
        return [
            "Without a current the gear is read through the closed loop, the load on the torque sensor: "
            "a constant drag in the gear and the part of its friction that differs by direction are held "
            f"by the speed loop's integral and leave no trace in the following error; {viscous}. Record "
            "the current to see them.",
            f"The gear's torques, in N m, rest on the declared actuator inertia ({j_gear:.4g} kg m^2); "
            "the load's are measured.",
            *gear,
        ]
    return [
        "Without a torque measurement (no current, no torque column) these cannot be seen: a constant "
        "load torque and the part of friction that differs by direction are held by the speed loop's "
        "integral and leave no trace in the following error; an inertia error trades off against the "
        f"loop's gain scale; {viscous}. Record the current (or an output torque sensor) to see them."
        + (" A coast after an alarm reads friction without the loop: what it named is above." * coast),
        "Every torque above, in N m, rests on the declared inertia "
        f"({axis.nominal_inertia_kgm2:.4g} kg m^2): an inertia off by x % scales them all by x %.",
        *gear,
    ]


__all__ = [
    "ARCSEC_PER_RAD",
    "CANDIDATES_WITHOUT_CURRENT",
    "NOT_IDENTIFIABLE",
    "TORQUE",
    "Loop",
    "closed_loop_signals",
    "friction_proxies",
    "loop_of",
    "not_identifiable_lines",
]
