"""The per-step loop of servo + plant, in plain float math (the hot path; no numpy inside).

Integrator: semi-implicit (symplectic) Euler with substeps. Per substep the forces are taken at
the current positions, velocities are updated (viscous friction implicitly, Coulomb friction by
a stick/slip clamp: when the friction impulse would reverse the speed, the speed becomes zero,
so an axis below its breakaway torque sticks instead of chattering), then positions move with the
new velocities. Symplectic Euler keeps the energy of the undamped spring bounded for
omega x h < 2; the substep count keeps omega_max x h <= MAX_OMEGA_H.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

# Stability/accuracy margin of the spring integration (symplectic Euler is stable below 2;
# at 0.4 the oscillation frequency is off by under 1 %).
MAX_OMEGA_H = 0.4


@dataclass
class KernelParams:
    """Everything the loop reads, flattened to floats (built by ServoAxis from model + settings)."""

    dt: float
    nsub: int  # substeps per servo period (1 for a rigid axis: no spring to resolve)
    direction: float
    kp: float
    kv: float
    tv_inv: float
    ff: float
    ilim: float
    kt: float
    jm: float
    jl: float
    j_total: float
    compliant: bool
    k1: float
    k2: float
    k3: float
    t1: float
    t2: float
    th1: float
    th2: float
    damping: float
    fc: float
    visc: float
    grav_a: float
    grav_phase: float
    offset: float
    rip_a: float
    rip_w: float
    rip_phase: float
    ke_a: float
    ke_w: float
    ke_phase: float
    lm_half: float
    resistance: float
    fc_pos_extra: float = 0.0  # asymmetric friction: level while turning CW (N m, on top of fc)
    fc_neg_extra: float = 0.0  # ... and while turning CCW (a magnitude)
    stribeck_a: float = 0.0  # Stribeck: extra breakaway torque at zero speed (N m)
    stribeck_v: float = 1.0  # its characteristic speed (rad/s)
    pulse_rad: float = 0.0  # > 0: feedback quantised to encoder pulses of this size
    speed_filter_alpha: float = 1.0  # first-order filter of the pulse-difference speed (1 = none)
    # the load beyond the flange's torque sensor: jl without the actuator's output flange (kg m^2)
    j_sensed: float = 0.0


@dataclass
class KernelState:
    """The integrated state; positions rad, speeds rad/s, output-referred, physical frame (CW +)."""

    xm: float = 0.0  # motor side, output-referred
    vm: float = 0.0
    xl: float = 0.0  # load side (flange + load); in the rigid model the lost-motion follower
    vl: float = 0.0
    integ: float = 0.0  # speed-loop integral term (rad/s, command frame)
    cprev: float = 0.0  # previous command (rad, command frame)
    current: float = 0.0  # A, physical frame
    vref: float = 0.0  # speed command (rad/s, command frame)
    # accumulators (cumulative)
    i2_integral: float = 0.0  # A^2 s
    i_integral: float = 0.0  # A s (a mean current over any window is its difference / the window)
    work_j: float = 0.0  # motor work on the axis (Kt i w), J
    regen_j: float = 0.0  # energy returned to the DC bus, J
    peak_speed: float = 0.0  # |motor-side speed| max, rad/s
    peak_error: float = 0.0  # |position error| max, rad
    brake_torque: float = 0.0  # N m, extra stiction on the motor side while the brake holds
    step_index: int = 0  # servo periods done
    rec_count: int = 0  # periods since the last recorded sample
    fb_prev: float | None = None  # quantised feedback of the previous period (rad, physical)
    v_filt: float = 0.0  # filtered pulse-difference speed (rad/s, physical)
    flange_torque: float = 0.0  # N m, what a torque sensor on the output flange reads (see run())


def run(p: KernelParams, s: KernelState, cmd: list[float] | None, n: int, servo_on: bool,
        rec: tuple[list, ...] | None = None, rec_every: int = 1,
        speed_injection: list[float] | None = None, *, record_at: Iterable[int] | None = None,
        accounting: bool = True) -> None:
    """Advance n servo periods. cmd: n command positions (rad, command frame), or None to hold.
    speed_injection: n speeds (rad/s, command frame) added to the speed command (an excitation
    at the speed loop's summing point), or None.

    rec: lists (t, cmd_phys, xm, xl, vm, current, vref, flange_torque) appended every rec_every
    periods, or only at the periods record_at names (increasing, 0 = the first of these n; rec_every
    is then unused): simulate() keeps only the periods its samples fall between.
    accounting: False skips the cumulative figures (integrals of I and I^2, work, regeneration,
    peaks) that only the simulated drive reads; the motion is the same.

    The flange torque (N m, physical frame) is what a strain-gauge sensor between the actuator's
    output flange and the load reads: the torque the flange exerts on the load, + = driving it CW;
    J_sensed x a_load = flange torque - T_load, where J_sensed (p.j_sensed) is the load beyond the
    sensor (jl less the actuator's flange) and T_load the load's own torques (gravity, load offset).
    With a compliant gear: the gear's twist torque (wind-up and damping, the last substep's) less what
    accelerates the flange; on a rigid axis, where the load moves with the motor side, J_sensed x the
    period's acceleration + T_load.
    """
    dt = p.dt
    rate = 1.0 / dt
    nsub = p.nsub
    if not p.compliant and nsub != 1:
        raise ValueError(f"a rigid axis takes one step per servo period, not {nsub}")
    h = dt / nsub
    d = p.direction
    kp, kv, tv_inv, ff, ilim, kt = p.kp, p.kv, p.tv_inv, p.ff, p.ilim, p.kt
    jm, jl, jt = p.jm, p.jl, p.j_total
    fc0 = p.fc + s.brake_torque
    visc = p.visc
    ga, gph, off = p.grav_a, p.grav_phase, p.offset
    ra, rw, rph = p.rip_a, p.rip_w, p.rip_phase
    kea, kew, keph = p.ke_a, p.ke_w, p.ke_phase
    lmh = p.lm_half
    res15 = 1.5 * p.resistance
    compliant = p.compliant
    k1, k2, k3, t1, t2, th1, th2, damp = p.k1, p.k2, p.k3, p.t1, p.t2, p.th1, p.th2, p.damping
    sin = math.sin
    floor = math.floor
    pq = p.pulse_rad
    quant = pq > 0.0
    alpha = p.speed_filter_alpha
    if quant and s.fb_prev is None:
        s.fb_prev = floor(s.xm / pq + 0.5) * pq
    # fb_prev is set whenever feedback is quantised, and only used then
    fb_prev, v_filt = (s.fb_prev if s.fb_prev is not None else 0.0), s.v_filt

    xm, vm, xl, vl = s.xm, s.vm, s.xl, s.vl
    integ, cprev, cur, vref = s.integ, s.cprev, s.current, s.vref
    i1, i2, work, regen, pk_v, pk_e = 0.0, 0.0, 0.0, 0.0, s.peak_speed, s.peak_error
    sin_ga = ga != 0.0
    sin_ra = ra != 0.0
    sin_ke = kea != 0.0
    has_lm = lmh > 0.0
    has_visc = visc != 0.0
    # motor-side inertia for one mass or two
    j_motor = jm if compliant else jt
    h_jm = h / j_motor
    visc_den = 1.0 / (1.0 + h * visc / j_motor)
    # friction impulses per substep, by direction (Coulomb + asymmetric; Stribeck added per substep)
    fcp_dv = h * (fc0 + p.fc_pos_extra) / j_motor
    fcn_dv = h * (fc0 + p.fc_neg_extra) / j_motor
    has_st = p.stribeck_a > 0.0
    st_dv = h * p.stribeck_a / j_motor
    st_iv = 1.0 / p.stribeck_v
    h_jl = h / jl
    if rec is not None:
        r_t, r_c, r_xm, r_xl, r_vm, r_i, r_vr, r_tf = rec
    rec_count = s.rec_count
    # the next period to record when record_at is given (-1: none left)
    at = iter(record_at) if record_at is not None else None
    next_at = next(at, -1) if at is not None else -1
    k0 = s.step_index + 1
    # flange torque: compliant, tg - flange_share x tl (the twist torque less the flange's share of
    # the load side's acceleration); rigid, j_sensed x (vm - v0) x rate + tload
    tg = tl = v0 = tload = 0.0
    j_sensed = p.j_sensed
    flange_share = 1.0 - j_sensed / jl

    for k in range(n):
        # ---------------- servo (command frame) ----------------
        if servo_on:
            c = cmd[k] if cmd is not None else cprev
            vc = (c - cprev) * rate
            cprev = c
            if quant:
                fbp = floor(xm / pq + 0.5) * pq
                v_filt += alpha * ((fbp - fb_prev) * rate - v_filt)
                fb_prev = fbp
                err = c - d * fbp
                vref = kp * err + ff * vc
                if speed_injection is not None:
                    vref += speed_injection[k]
                ev = vref - d * v_filt
            else:
                err = c - d * xm
                vref = kp * err + ff * vc
                if speed_injection is not None:
                    vref += speed_injection[k]
                ev = vref - d * vm
            integ_new = integ + ev * dt * tv_inv
            ic = kv * (ev + integ_new)
            if ic > ilim:
                ic = ilim
                if ev < 0.0:  # integrate only when it leads out of saturation
                    integ = integ_new
            elif ic < -ilim:
                ic = -ilim
                if ev > 0.0:
                    integ = integ_new
            else:
                integ = integ_new
            cur = d * ic
            ae = err if err >= 0.0 else -err
            if ae > pk_e:
                pk_e = ae
        else:
            cur = 0.0
            integ = 0.0
            vref = 0.0
        motor_torque = kt * cur

        # ---------------- plant ----------------
        if compliant:
            for _ in range(nsub):
                tw = xm - xl
                if sin_ke:
                    tw += kea * sin(kew * xm + keph)
                contact = True
                if has_lm:
                    if tw > lmh:
                        tw -= lmh
                    elif tw < -lmh:
                        tw += lmh
                    else:
                        contact = False
                if contact:
                    a = tw if tw >= 0.0 else -tw
                    if a <= th1:
                        tg = k1 * a
                    elif a <= th2:
                        tg = t1 + k2 * (a - th1)
                    else:
                        tg = t2 + k3 * (a - th2)
                    if tw < 0.0:
                        tg = -tg
                    tg += damp * (vm - vl)
                    if has_lm and tg * tw < 0.0:  # a dead-band contact pushes, never pulls
                        tg = 0.0
                else:
                    tg = 0.0
                vm = _motor_speed(vm, xm, motor_torque - tg, h_jm, sin_ra, ra, rw, rph, has_visc, visc_den,
                                  fcp_dv, fcn_dv, has_st, st_iv, st_dv)
                tl = tg - off
                if sin_ga:
                    tl -= ga * sin(xl + gph)
                vl += h_jl * tl
                xm += h * vm
                xl += h * vl
        else:
            # one rigid mass: no spring to resolve, one step per period (nsub is 1)
            tload = off
            if sin_ga:
                tload += ga * sin(xm + gph)
            v0 = vm
            vm = _motor_speed(vm, xm, motor_torque - tload, h_jm, sin_ra, ra, rw, rph, has_visc, visc_den,
                              fcp_dv, fcn_dv, has_st, st_iv, st_dv)
            xm += h * vm
            vl = vm
            # load = motor side + kinematic error, through the lost-motion play operator
            lp = xm + kea * sin(kew * xm + keph) if sin_ke else xm
            if has_lm:
                if xl < lp - lmh:
                    xl = lp - lmh
                elif xl > lp + lmh:
                    xl = lp + lmh
            else:
                xl = lp

        if not servo_on:
            c = cprev = d * xm  # the error counter follows the feedback while the servo is off
            if quant:  # the drive keeps counting pulses
                fbp = floor(xm / pq + 0.5) * pq
                v_filt += alpha * ((fbp - fb_prev) * rate - v_filt)
                fb_prev = fbp

        # ---------------- accounting ----------------
        if accounting:
            i1 += cur
            i2 += cur * cur
            pm = motor_torque * vm
            work += pm
            pe = pm + res15 * cur * cur
            if pe < 0.0:
                regen -= pe
            av = vm if vm >= 0.0 else -vm
            if av > pk_v:
                pk_v = av
        take = False  # this period is recorded: one of record_at's, or every rec_every-th
        if at is not None:
            if k == next_at:
                next_at = next(at, -1)
                take = True
        elif rec is not None:
            rec_count += 1
            if rec_count >= rec_every:
                rec_count = 0
                take = True
        if take:
            r_t.append((k0 + k) * dt)
            r_c.append(d * c)
            r_xm.append(xm)
            r_xl.append(xl)
            r_vm.append(vm)
            r_i.append(cur)
            r_vr.append(vref)
            r_tf.append(tg - flange_share * tl if compliant else j_sensed * (vm - v0) * rate + tload)

    s.xm, s.vm, s.xl, s.vl = xm, vm, xl, vl
    s.integ, s.cprev, s.current, s.vref = integ, cprev, cur, vref
    s.i_integral += i1 * dt
    s.i2_integral += i2 * dt
    s.work_j += work * dt
    s.regen_j += regen * dt
    s.peak_speed, s.peak_error = pk_v, pk_e
    s.step_index += n
    s.fb_prev, s.v_filt = fb_prev, v_filt
    s.rec_count = rec_count
    if n > 0:
        s.flange_torque = tg - flange_share * tl if compliant else j_sensed * (vm - v0) * rate + tload


def _motor_speed(vm: float, xm: float, tm: float, h_jm: float, sin_ra: bool, ra: float, rw: float,
                 rph: float, has_visc: bool, visc_den: float, fcp_dv: float, fcn_dv: float,
                 has_st: bool, st_iv: float, st_dv: float) -> float:
    """The motor side's speed after one step of ``h`` (``h_jm`` = h / jm) under the torque ``tm``
    on it (besides the ripple and the friction): the torque ripple, viscous friction implicitly,
    then Coulomb and Stribeck friction by the stick/slip clamp. The rigid and the compliant plant
    step the motor side by this one rule."""
    if sin_ra:
        tm -= ra * math.sin(rw * xm + rph)
    v = vm + h_jm * tm
    if has_visc:
        v *= visc_den
    up, dn = fcp_dv, fcn_dv
    if has_st:
        q = vm * st_iv
        e = st_dv * math.exp(-q * q)
        up += e
        dn += e
    if v > up:
        return v - up
    if v < -dn:
        return v + dn
    return 0.0


def substeps_for(jm: float, jl: float, k_max: float, dt: float) -> int:
    """Substeps per servo period so that omega_max x h <= MAX_OMEGA_H for the stiffest region."""
    omega = math.sqrt(k_max * (1.0 / jm + 1.0 / jl))
    return max(1, math.ceil(omega * dt / MAX_OMEGA_H))
