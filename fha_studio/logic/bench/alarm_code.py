"""The alarm code lines ALM-A ... ALM-D of a drive's CN2, in the manual's words (no Qt).

On an alarm the HA-655 puts a 4-bit code on ALM-D C B A (ON = 1); several alarms share a code
(1101 is every encoder alarm, 50 ... 57), so a code names the alarms it can be, from the
driver's alarm table (``resources/drive/ha655-alarms.toml``); the display's 2-digit code tells
them apart.
"""

from __future__ import annotations

from collections.abc import Sequence

from fha_studio.hardware.parameters import Alarm, load_alarm_table

#: The lines, bit 0 ... bit 3 of the code, as the manual names them.
LINES = ("ALM-A", "ALM-B", "ALM-C", "ALM-D")


def alarms_of_code(code: int, driver: str = "HA-655", absolute_encoder: bool | None = None,
                   unmapped: Sequence[str] = ()) -> list[Alarm]:
    """The alarms of ``driver``'s table whose 4-bit code is ``code`` (none for 0) on the lines
    that are read (``unmapped``: the lines no channel reads, which may be either); without the
    absolute-encoder-only ones when the encoder is known to be incremental."""
    if not code and not unmapped:
        return []
    known = 0b1111 & ~sum(1 << LINES.index(line) for line in unmapped)
    return [a for a in load_alarm_table(driver) if a.alm_bits & known == code & known
            and not (a.absolute_only and absolute_encoder is False)]


def code_text(code: int, driver: str = "HA-655", absolute_encoder: bool | None = None,
              unmapped: Sequence[str] = ()) -> str:
    """``"ALM-D C B A 0010: 60 Error counter overflow"``, ``"... 0000: no alarm"``, or the code no
    alarm of the table has; ``unmapped``: the lines no channel reads, shown as ``?`` (the alarms
    named are those the lines that are read allow)."""
    digits = "".join("?" if LINES[bit] in unmapped else str(code >> bit & 1) for bit in (3, 2, 1, 0))
    text = f"ALM-D C B A {digits}: "
    alarms = alarms_of_code(code, driver, absolute_encoder, unmapped) if code else []
    if not code:
        text += "no alarm" if not unmapped else "no alarm on the lines that are read"
    elif alarms:
        text += ", ".join(f"{a.code} {a.name}" for a in alarms)
        if len(alarms) > 1:
            text += " (the front panel's 2-digit code tells which)"
    else:
        text += f"no alarm of the {driver} table has this code"
    if unmapped:
        text += f" ({', '.join(unmapped)} not mapped)"
    return text
