"""What more than one test module needs, in one place (imported as ``tests.support.*``).

- ``scripted``: ``ScriptedDrive``, a stand-in drive on a pipe end answering from a handler.
- ``documented``: ``DocumentedDrive``, the one drive of the manual's DGR and OWW (a handler).
- ``links``: the fixtures ``pipes``, ``scripted`` and ``client_for`` (a client on a scripted
  drive), offered to every test.
- ``processes``: ``Child``, a program in a process of its own (``Child.sim``: ``fha-studio sim``
  and its address), ended the one way (``stop``); the fixture ``children``.
- ``windows`` (Qt): ``torn_down``, the one teardown of the GUI tests' window factories.
- ``clock``: ``FakeClock``, the one injected clock (the calendar and a count of seconds, moved
  together).
- ``read_only``: ``ReadOnlyPlace``, files the program really cannot write (chmod, and where the
  tests run as root the program without root's overrides of a file's mode, through setpriv), and
  the program run on them in a subprocess; its pieces serve scripts/hostile_inputs.py too.

No module here imports Qt at import time unless its name says it is for the GUI tests: the core
tests run without Qt.
"""
