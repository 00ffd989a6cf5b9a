"""FHA Studio: commissioning tool for Harmonic Drive FHA-C actuators on HA-655 / HA-675 drivers.

Layers (enforced by tests/test_architecture.py):
    gui, cli  ->  logic  ->  hardware  ->  physics  ->  catalog
Only ``fha_studio.gui`` imports Qt.
"""

__version__ = "0.1.0"
