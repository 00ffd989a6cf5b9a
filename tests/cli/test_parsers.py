"""Every argument parser takes options only as written: argparse's prefix matching would take a
mistyped ``--model FILE`` as ``--model-out FILE`` and overwrite FILE."""

from __future__ import annotations

import argparse

import pytest

from fha_studio.cli import build_parser
from fha_studio.main import main


def _every_parser(parser: argparse.ArgumentParser, name: str = "fha-studio"):
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _every_parser(sub, f"{name} {sub_name}")


def test_every_parser_refuses_abbreviated_options():
    from fha_studio.gui.app import _parser as gui_parser

    parsers = [*_every_parser(build_parser()), ("fha-studio gui", gui_parser())]
    assert len(parsers) > 20  # the walk reached the sub-commands' own sub-commands
    abbreviating = [name for name, parser in parsers if parser.allow_abbrev]
    assert abbreviating == []


def test_a_prefix_of_an_output_option_is_refused_and_writes_nothing(tmp_path, capsys):
    from fha_studio.physics import AxisModel  # noqa: F401  (the command's module loads)

    model = tmp_path / "model.toml"
    model.write_text("kept = true\n")
    recording = tmp_path / "rec.csv"
    recording.write_text("t,pos\n0,0\n0.001,0\n")
    with pytest.raises(SystemExit) as exit_:
        main(["discrepancy", str(recording), "--model", str(model)])
    assert exit_.value.code == 2
    assert "--model" in capsys.readouterr().err
    assert model.read_text() == "kept = true\n"


@pytest.mark.parametrize("args", [
    ["register", "--d", "x.sqlite", "machines"],
    ["register", "machines", "--js"],
    ["size", "--accel", "0.1"],
])
def test_abbreviated_options_are_unknown(args, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(args)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1


def test_the_cli_lists_gui_without_options_of_its_own_and_gui_help_is_the_guis(capsys):
    """The entry point hands ``fha-studio gui ...`` to the GUI's parser: an option on the CLI's
    ``gui`` entry would be shown by no help and read by nothing."""
    from fha_studio.gui.app import _parser as gui_parser

    (gui,) = [sub for name, sub in _every_parser(build_parser()) if name == "fha-studio gui"]
    assert [a.option_strings for a in gui._actions] == [["-h", "--help"]]
    with pytest.raises(SystemExit):
        main(["gui", "--help"])
    shown = capsys.readouterr().out
    for action in gui_parser()._actions:
        if action.help != argparse.SUPPRESS:
            assert all(option in shown for option in action.option_strings)
