"""What the scope's indicator claims about live data (no Qt): LIVE only while the newest sample is
current, else NOT LIVE with the reason, and PAUSED while the picture is held."""

from __future__ import annotations

from enum import StrEnum

from fha_studio.logic.scope.acquisition import LiveStatus

#: A sample this old is no longer live [s], at the least (else five sample periods).
STALE_AFTER_MIN_S = 0.5


class IndicatorKind(StrEnum):
    """The indicator's colour."""

    LIVE = "live"
    NOT = "not"
    PAUSED = "paused"


def live_indicator(
    status: LiveStatus | None, newest_age_s: float | None, paused: bool
) -> tuple[IndicatorKind, str]:
    """The indicator of a live view: ``status`` the acquisition's last (None before the first),
    ``newest_age_s`` how old the newest sample drawn is (None: no sample yet)."""
    kind = IndicatorKind.NOT
    if status is None:
        text = "NOT LIVE: waiting for the first sample"
    elif not status.live:
        text = status.label
    else:
        stale_after = max(STALE_AFTER_MIN_S, 5.0 / status.rate_hz) if status.rate_hz else STALE_AFTER_MIN_S
        if newest_age_s is None or newest_age_s > stale_after:
            age = "a while" if newest_age_s is None else f"{newest_age_s:.1f} s"
            text = f"NOT LIVE: no new sample for {age}"
        else:
            kind, text = IndicatorKind.LIVE, status.label
    if paused:
        text = "PAUSED (acquisition goes on)" if kind is IndicatorKind.LIVE else f"PAUSED · {text}"
        kind = IndicatorKind.PAUSED
    return kind, text
