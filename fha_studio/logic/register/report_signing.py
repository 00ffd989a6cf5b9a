"""Signing a commissioning report with a person's key: the HTML file carries its signature, the
register records it (the PDF, which cannot carry one, is found in the register by its hash).

Nothing is half-done: the key is loaded and checked against the register before anything is
written; the register's record comes before the file, and the session file is saved last (a
failure on the way leaves the session unsigned, as it was)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from fha_studio import clock, fileio
from fha_studio.logic.procedures.report import build_report, render_html, sign
from fha_studio.logic.procedures.session import ProcedureSession
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.keys import Keys, SigningKey
from fha_studio.logic.register.signing import (
    Signed,
    SigningError,
    default_key_path,
    key_id_of,
    keys_dir,
    public_raw,
    sign_bytes,
    with_block,
)


def usable_key(register: Keys, key: Ed25519PrivateKey, person: str) -> SigningKey:
    """The register's record of ``key``, when ``person`` may sign with it (else RegisterError)."""
    key_id = key_id_of(public_raw(key))
    known = register.signing_key(key_id)
    if known is None:
        raise RegisterError(f"key {key_id} is not in the register (fha-studio register keys add makes one)")
    if known.person != person.strip():
        raise RegisterError(f"key {key_id} is {known.person}'s: {person.strip()} cannot sign with it")
    if known.revoked_utc:
        raise RegisterError(f"key {key_id} of {known.person} was revoked at {known.revoked_utc}")
    return known


def private_key_file_for(register: Keys, person: str) -> Path | None:
    """The private key file of ``person``'s newest usable key in the user's keys folder; None
    when the person has no key in the register. SigningError when the person has keys but none
    of them is on this computer."""
    keys = [k for k in register.signing_keys(person) if not k.revoked_utc]
    if not keys:
        return None
    for key in reversed(keys):
        path = default_key_path(key.key_id)
        if path.is_file():
            return path
    ids = ", ".join(k.key_id for k in keys)
    raise SigningError(f"{person.strip()} signs with key {ids}, whose private key is not in {keys_dir()}: "
                       "give its key file")


def sign_report_file(
    register: Keys,
    session: ProcedureSession,
    who: str,
    key: Ed25519PrivateKey,
    output: str | Path,
    context: Mapping[str, Any] | None = None,
) -> Signed:
    """Sign the session's report as ``who`` with ``key`` and write it to ``output`` (HTML, its
    signature the last line); the signature is recorded in the register. SignError while checks
    are open; RegisterError when the key is not ``who``'s usable key in the register."""
    known = usable_key(register, key, who)
    target = fileio.check_output_path(output)
    before = dict(session.signature)
    try:
        sign(session, who, context, key_id=known.key_id, save=False)
        content = render_html(build_report(session, context)).encode("utf-8")
        signed = sign_bytes(key, content, known.person, session.signature["at_utc"])
        register.record_signature(signed, target)
        fileio.write_bytes(target, with_block(content, signed))
    except BaseException:
        session.signature = before
        raise
    if session.path is not None:
        session.save()
    return signed


def sign_other_file(register: Keys, key: Ed25519PrivateKey, who: str, path: str | Path) -> Signed:
    """Sign a file that cannot carry its signature (the report's PDF): recorded in the register."""
    known = usable_key(register, key, who)
    signed = sign_bytes(key, fileio.read_bytes(path), known.person, clock.utc_iso())
    register.record_signature(signed, path)
    return signed
