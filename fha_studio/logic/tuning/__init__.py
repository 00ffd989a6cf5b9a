"""Tuning: the speed loop's frequency response, the gear's resonance, the load inertia and
proposed gains. No Qt.

- ``linear``: the loops of the physics model linearised (python-control, discrete time);
- ``excitation``: the PRBS's amplitude and the angle it may travel, stated before it starts;
- ``response``: H1 and coherence from measured records, resonance, inertia, margins;
- ``propose``: tune items for an aim (stiff / standard / soft).
"""
