"""Bench captures decoded (no Qt): :mod:`.decode` (encoder, Z, command pulses, SPD-MON, the edge-rate
check) and :mod:`.importer` (roles mapped to capture channels, made into a recording)."""
