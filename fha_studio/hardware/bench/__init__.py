"""Bench instruments: what a logic analyzer, an oscilloscope or a DAQ captured on the drive's CN2
(no Qt).

- :mod:`.capture`: :class:`~.capture.SampleBlock` (a block of samples as an instrument delivers
  it, live or from a file) and :class:`~.capture.Capture` (a whole capture of one file).
- :mod:`.readers`: sigrok sessions (``.sr``), VCD (IEEE 1364), ``sigrok-cli``'s CSV, a
  generic CSV with a time column (oscilloscopes' preambles and units rows included), Saleae
  Logic's export of changes, Rigol's and older Tektronix scopes' CSVs;
  :func:`~.readers.read_capture` picks by content.
- :mod:`.writers`: the sigrok forms and the generic CSV written (the virtual bench instrument of
  the simulated drive).
"""
