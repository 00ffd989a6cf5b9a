"""The scope's live view on a drive that gives it no channel to poll (the documented profile with
an incremental encoder: DGR answers x, and nothing else is documented) says why it is not live
instead of failing on an empty channel list."""

from __future__ import annotations

CODE = "FHA-25C-50-US250"


def test_live_with_no_channel_to_poll_says_so(make_window, qtbot):
    window = make_window(connect=f"sim://{CODE}?paced=0&profile=documented")
    window.state.set_actuator(CODE, acknowledged=True)
    view = window.show_page("scope").view
    view.start_live()
    qtbot.waitUntil(lambda: view._live is not None, timeout=10000)
    assert view._live.channels == () and view._levels is None
    qtbot.waitUntil(lambda: view.indicator_text().startswith("NOT LIVE"), timeout=10000)
    view.stop_live()
