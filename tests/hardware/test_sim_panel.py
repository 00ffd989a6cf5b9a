"""The embedded simulated drive's panel is a typed handle of the client (DriveClient.sim_panel):
there for a sim:// port, None for any other drive."""

from __future__ import annotations

import pytest

from fha_studio.hardware.api import SimPanel
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.sim import SimRefused
from tests.support.documented import DocumentedDrive


def test_a_sim_port_has_the_panel_of_its_drive():
    with DriveClient.open("sim://FHA-25C-50-S248-B?paced=0&profile=documented") as client:
        panel = client.sim_panel
        assert isinstance(panel, SimPanel) and not panel.has_sensors
        with pytest.raises(SimRefused, match="brake holds"):
            panel.turn_by_hand(5.0)
        panel.release_brake(True)
        assert panel.io_state().brake_released
        before = client.absolute_position()
        panel.turn_by_hand(5.0)
        assert client.absolute_position() - before == pytest.approx(5 * 8192 * 50 / 360, abs=1)
        panel.release_brake(False)
        assert not panel.io_state().brake_released


def test_any_other_drive_has_no_panel(client_for):
    client, _ = client_for(DocumentedDrive())
    assert client.sim_panel is None
