"""Takes the README's screenshot of a conflict settled in the register dialog.

    QT_QPA_PLATFORM=offscreen python docs/screenshots/take_register_conflicts.py [OUTDIR] [WIDTHxHEIGHT]

Two technicians' laptops changed the table axis of "Line 3 positioner" while apart (Ana read the
rotary direction reversed and In-position range 10, Ben read them normal and 25; both set the
origin) and were synced: the machine window's Register dialog on Ben's laptop shows the two
conflicts, the parameters' sides side by side, Ana's side chosen with a reason. The dialog is
shown at the size given (default 1280x720, the window on a 1366x768 screen). The registers,
settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import sys
from pathlib import Path

from shots import ScreenshotRun, private_folder

TMP = Path(private_folder())
SIZE = tuple(int(n) for n in (sys.argv[2] if len(sys.argv) > 2 else "1280x720").split("x"))
M = "Line 3 positioner"


def laptop(path: Path, who: str, direction: int, in_position: int, at: str, origin: str) -> None:
    """A laptop's register (named after the laptop, as on the laptop: ``ana-laptop register.sqlite``)."""
    import socket

    from fha_studio.logic.register import Register

    real = socket.gethostname
    socket.gethostname = lambda: f"{who.split()[0].lower()}-laptop"
    try:
        reg = Register(path)
    finally:
        socket.gethostname = real
    with reg:
        reg.ensure_axis(M, "table", who=who, actuator_code="FHA-25C-50-US250", driver_model="HA-655-2-200")
        reg.ensure_axis(M, "tilt", who=who, actuator_code="FHA-32C-100-S248-B", driver_model="HA-655-2-200")
        reg.record_snapshot(
            f"{M}/table",
            [("system", 8, "rotary_direction", direction), ("tune", 4, "in_position_range", in_position)],
            "link",
            who=who,
            at_utc=at,
        )
        reg.record_origin(
            f"{M}/table", f"absolute origin set (OWW), read back at {origin}", who=who, at_utc=at
        )


def main() -> int:
    from fha_studio.gui.register_dialog import RegisterDialog
    from fha_studio.logic.register import Register
    from fha_studio.logic.register.sync import sync_registers
    from fha_studio.paths import user_data_dir

    # Ben's register where FHA Studio keeps it (the dialog names it), Ana's brought on a stick
    ana, ben = TMP / "ana" / "register.sqlite", user_data_dir() / "register.sqlite"
    for path in (ana, ben):
        path.parent.mkdir(parents=True)
    laptop(ana, "Ana Lima", 1, 10, "2026-12-05T08:12:40Z", "+0.01°")
    laptop(ben, "Ben Okafor", 0, 25, "2026-12-05T09:30:05Z", "+0.00°")
    sync_registers(ana, ben, who="Ben Okafor")
    register = Register(ben)
    run = ScreenshotRun((SIZE[0], SIZE[1]), make_window=lambda: RegisterDialog(
        register, M, "table", operator=lambda: "Carla Reviewer"))
    dialog = run.window
    parameters = next(c for c in register.conflicts() if c.subject == "parameters")
    dialog.show_conflict(parameters.short)
    c = dialog.current_conflict()
    assert c is not None and c.subject == "parameters", c
    ana_side = next(n for n, s in enumerate(c.sides, 1) if s.values["rotary_direction"].who == "Ana Lima")
    dialog.keep_group.button(ana_side).click()
    dialog.settle_note.setText("checked on the machine: the table turns CCW on FWD, as Ana read")
    run.settle(0.5)
    run.shot("register-conflicts")
    run.close()
    register.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
