"""Signatures that mean something: each person's Ed25519 key, a report signed with it, and
``fha-studio register verify``: the signed file passes, a changed byte fails (exit 5)."""

from __future__ import annotations

import json
import os
import shutil
import stat

import pytest

from fha_studio.cli import main
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.register import Register
from fha_studio.logic.register.signing import keys_dir
from tests.procedures.walk import walk

CODE = "FHA-25C-50-US250-B-L"
ALL = ["receiving-inspection", "installation", "wiring", "sensor-adjustment", "rotary-direction"]


@pytest.fixture(scope="module")
def finished_once(tmp_path_factory):
    """A session with every procedure done, walked once for the module (1-1.5 s a walk under load)."""
    folder = tmp_path_factory.mktemp("finished")
    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee", site="Line 3")
    session.driver = {"model": "HA-655-2-200", "adjusted_for": CODE, "version": "sim 1"}
    session.save(folder / "axis1.json")
    for procedure_id in ALL:
        walk(ProcedureRun(session, load_procedure(procedure_id, context)))
    return folder


@pytest.fixture
def finished(finished_once, tmp_path):
    """A session with every procedure done (nothing open: it may be signed): the test's own copy
    of what the walk left."""
    shutil.copytree(finished_once, tmp_path, dirs_exist_ok=True)
    return tmp_path / "axis1.json"


@pytest.fixture
def reg_path(register_target, monkeypatch):
    """The register, a file or a database on the tests' PostgreSQL server (each test runs on both)."""
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "correct horse")
    return register_target


def _add_key(reg_path, name, *extra):
    return main(["register", "--register", str(reg_path), "keys", "add", "--name", name, *extra])


def _verify(reg_path, report, capsys):
    capsys.readouterr()
    code = main(["register", "--register", str(reg_path), "verify", str(report), "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_a_signed_report_verifies_and_a_changed_byte_fails(finished, reg_path, tmp_path, capsys, fixed_clock):
    assert _add_key(reg_path, "A. Reviewer", "--json") == 0
    made = json.loads(capsys.readouterr().out)
    key_file = keys_dir() / f"{made['key_id']}.pem"
    assert made["key_file"] == str(key_file) and made["encrypted"]
    assert stat.S_IMODE(os.stat(key_file).st_mode) == 0o600
    assert b"ENCRYPTED PRIVATE KEY" in key_file.read_bytes()

    report = tmp_path / "axis1.html"
    assert main(["procedures", "report", str(finished), "-o", str(report), "--sign", "A. Reviewer",
                 "--register", str(reg_path)]) == 0
    html = report.read_text()
    assert "fha-studio register verify REPORT" in html and made["key_id"] in html
    assert ProcedureSession.load(finished).signature["key_id"] == made["key_id"]

    code, verdict = _verify(reg_path, report, capsys)
    assert code == 0 and verdict["valid"] and verdict["reason"] == ""
    assert (verdict["signer"], verdict["key_id"]) == ("A. Reviewer", made["key_id"])
    assert verdict["signed_utc"].startswith("2026-11-30T07:00")
    assert main(["register", "--register", str(reg_path), "verify", str(report)]) == 0
    assert "signed by A. Reviewer" in capsys.readouterr().out

    data = bytearray(report.read_bytes())
    at = data.index(b"Line 3")
    data[at] ^= 0x01  # one bit of one byte of the report's text
    report.write_bytes(bytes(data))
    code, verdict = _verify(reg_path, report, capsys)
    assert code == 5 and not verdict["valid"] and "changed since it was signed" in verdict["reason"]
    assert main(["register", "--register", str(reg_path), "verify", str(report)]) == 5
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "changed since it was signed" in err


def test_a_changed_signature_line_or_signer_fails(finished, reg_path, tmp_path, capsys):
    _add_key(reg_path, "A. Reviewer")
    report = tmp_path / "r.html"
    main(["procedures", "report", str(finished), "-o", str(report), "--sign", "A. Reviewer",
          "--register", str(reg_path)])
    signed = report.read_bytes()
    report.write_bytes(signed.replace(b'"signer":"A. Reviewer"', b'"signer":"B. Someone"'))
    code, verdict = _verify(reg_path, report, capsys)
    assert code == 5 and "but key" in verdict["reason"]
    report.write_bytes(signed[:-10] + b"0" + signed[-9:])  # a digit of the signature itself
    code, verdict = _verify(reg_path, report, capsys)
    assert code == 5 and not verdict["valid"]
    report.write_bytes(signed + b"<p>added</p>\n")
    code, verdict = _verify(reg_path, report, capsys)
    assert code == 5 and "damaged or has text after it" in verdict["reason"]


def test_unknown_key_no_signature_and_not_a_report(finished, reg_path, tmp_path, capsys):
    _add_key(reg_path, "A. Reviewer")
    unsigned = tmp_path / "unsigned.html"
    assert main(["procedures", "report", str(finished), "-o", str(unsigned)]) == 0
    report = tmp_path / "r.html"
    main(["procedures", "report", str(finished), "-o", str(report), "--sign", "A. Reviewer",
          "--register", str(reg_path)])
    # the signed report written again from the signed session is the same bytes: it verifies
    again = tmp_path / "again.html"
    assert main(["procedures", "report", str(finished), "-o", str(again)]) == 0
    assert _verify(reg_path, again, capsys)[0] == 0
    other = tmp_path / "other.sqlite"
    Register(other).close()
    code, verdict = _verify(other, report, capsys)
    assert code == 5 and "does not know" in verdict["reason"]

    code, verdict = _verify(reg_path, unsigned, capsys)
    assert code == 5 and "no signature" in verdict["reason"]

    notes = tmp_path / "notes.txt"
    notes.write_text("shopping list\n")
    code, verdict = _verify(reg_path, notes, capsys)
    assert code == 5 and "not a commissioning report" in verdict["reason"]
    assert main(["register", "--register", str(reg_path), "verify", str(tmp_path / "missing.html")]) == 2


def test_a_signer_without_a_key_signs_by_name_only(finished, reg_path, tmp_path, capsys):
    _add_key(reg_path, "A. Reviewer")
    report = tmp_path / "r.html"
    assert main(["procedures", "report", str(finished), "-o", str(report), "--sign", "T. Trainee",
                 "--register", str(reg_path)]) == 0
    assert "signed by name only" in capsys.readouterr().err
    assert "Signed by name only" in report.read_text()
    assert _verify(reg_path, report, capsys)[0] == 5


def test_bad_keys_and_passphrases_are_one_line_and_write_nothing(
        finished, reg_path, tmp_path, capsys, monkeypatch):
    key_file = tmp_path / "mine.pem"
    assert _add_key(reg_path, "A. Reviewer", "--key-file", str(key_file)) == 0
    assert _add_key(reg_path, "A. Reviewer", "--key-file", str(key_file)) == 2  # never replaced
    assert "already exists" in capsys.readouterr().err
    report = tmp_path / "r.html"
    session_before = finished.read_bytes()

    def refused(*extra, words):
        capsys.readouterr()
        code = main(["procedures", "report", str(finished), "-o", str(report), "--sign", "A. Reviewer",
                     "--register", str(reg_path), *extra])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1 and words in err, err
        assert not report.exists() and finished.read_bytes() == session_before

    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "wrong")
    refused("--key-file", str(key_file), words="wrong passphrase")
    monkeypatch.delenv("FHA_STUDIO_KEY_PASSPHRASE")
    refused("--key-file", str(key_file), words="it is encrypted: give its passphrase")
    refused("--key-file", str(tmp_path / "none.pem"), words="none.pem")
    corrupt = tmp_path / "corrupt.pem"
    corrupt.write_bytes(b"-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n")
    refused("--key-file", str(corrupt), words="not a private key")
    refused(words="not in")  # A. Reviewer's key is not in the user's keys folder
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "")
    stranger = tmp_path / "stranger.pem"
    assert _add_key(tmp_path / "elsewhere.sqlite", "A. Reviewer", "--key-file", str(stranger)) == 0
    refused("--key-file", str(stranger), words="is not in the register")
    assert main(["register", "--register", str(reg_path), "keys", "list", "--json"]) == 0
    keys = json.loads(capsys.readouterr().out)
    assert [k["person"] for k in keys] == ["A. Reviewer"]


def test_every_wrong_passphrase_is_said_as_one(tmp_path):
    """A wrong passphrase decrypts to garbage, and now and then the garbage has valid padding so
    the parser calls the key damaged instead: that passphrase must still be said to be wrong."""
    from cryptography.hazmat.primitives import serialization

    from fha_studio.logic.register.signing import SigningError, load_private_key, new_key

    key_file = tmp_path / "mine.pem"
    key_file.write_bytes(new_key().private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
        serialization.BestAvailableEncryption(b"right")))
    data = key_file.read_bytes()
    for attempt in range(20_000):  # about one in 256 fails as damaged data
        guess = f"wrong {attempt}"
        try:
            serialization.load_pem_private_key(data, password=guess.encode())
        except ValueError as exc:
            if "password" not in str(exc).lower():
                break
    else:
        pytest.fail("no passphrase that decrypts to damaged data")
    with pytest.raises(SigningError, match="wrong passphrase"):
        load_private_key(key_file, guess)
    assert load_private_key(key_file, "right") is not None


def test_a_key_is_never_replaced_and_a_revocation_is_a_fact_of_its_own(register_target):
    from fha_studio.logic.register.signing import key_id_of, new_key, public_raw

    with Register(register_target) as reg:
        key = new_key()
        key_id = key_id_of(public_raw(key))
        reg.add_key("A. Reviewer", public_raw(key).hex(), key_id)
        with pytest.raises(Exception, match="already in the register"):
            reg.add_key("B. Other", public_raw(key).hex(), key_id)
        reg.revoke_key(key_id, "laptop lost")
        [kept] = reg.signing_keys("A. Reviewer")
        assert kept.revoked_reason == "laptop lost" and kept.person == "A. Reviewer"


def test_a_revoked_key_signs_nothing_more_and_what_it_signed_still_verifies(
        finished, reg_path, tmp_path, capsys):
    assert _add_key(reg_path, "A. Reviewer", "--json") == 0
    key_id = json.loads(capsys.readouterr().out)["key_id"]
    report = tmp_path / "r.html"
    assert main(["procedures", "report", str(finished), "-o", str(report), "--sign", "A. Reviewer",
                 "--register", str(reg_path)]) == 0
    revoke = ["register", "--register", str(reg_path), "keys", "revoke"]
    assert main([*revoke, key_id, "--reason", "laptop lost"]) == 0
    assert "revoked" in capsys.readouterr().out
    assert _verify(reg_path, report, capsys)[0] == 0  # signed before the revocation
    assert main([*revoke, key_id]) == 2
    assert main([*revoke, "0000000000000000"]) == 2
    again = tmp_path / "again.html"
    capsys.readouterr()
    assert main(["procedures", "report", str(finished), "-o", str(again), "--sign", "A. Reviewer",
                 "--register", str(reg_path)]) == 0  # no usable key left: by name only, said so
    assert "signed by name only" in capsys.readouterr().err


def test_the_passphrase_is_asked_twice_on_a_terminal(reg_path, tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("FHA_STUDIO_KEY_PASSPHRASE")
    monkeypatch.setattr("sys.stdin.isatty", lambda: True)
    answers = iter(["one", "two", "same", "same"])
    monkeypatch.setattr("getpass.getpass", lambda prompt="": next(answers))
    key_file = tmp_path / "k.pem"
    assert _add_key(reg_path, "A. Reviewer", "--key-file", str(key_file)) == 2
    assert "the two passphrases differ" in capsys.readouterr().err and not key_file.exists()
    assert isinstance(reg_path, str) or not reg_path.exists()  # no register made for it either
    assert _add_key(reg_path, "A. Reviewer", "--key-file", str(key_file)) == 0
    assert "encrypted with the passphrase" in capsys.readouterr().out
    assert main(["register", "--register", str(reg_path), "keys", "list", "--json"]) == 0
    assert len(json.loads(capsys.readouterr().out)) == 1  # the refused one left nothing
