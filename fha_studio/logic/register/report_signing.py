"""Signing a commissioning report with a person's key: the HTML file carries its signature, the
register records it (the PDF, which cannot carry one, is found in the register by its hash).

The report's HTML is reproducible from the session, so the signature is made once, when the
person signs, and kept in the session file; every report written from that session carries it.
Nothing is half-done: the key is checked against the register before anything is written; the
register's record comes before the session file (a failure on the way leaves the session
unsigned, as it was)."""

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


def sign_session(
    register: Keys,
    session: ProcedureSession,
    who: str,
    key: Ed25519PrivateKey,
    context: Mapping[str, Any] | None = None,
) -> Signed:
    """Sign the session's report as ``who`` with ``key``: the signature covers the report's HTML
    as :func:`report_file_bytes` writes it, is recorded in the register and kept in the session
    (saved). SignError while checks are open; RegisterError when the key is not ``who``'s usable
    key in the register; on either the session is as it was."""
    known = usable_key(register, key, who)
    before = dict(session.signature)
    try:
        sign(session, who, context, key_id=known.key_id, save=False)
        content = render_html(build_report(session, context)).encode("utf-8")
        signed = sign_bytes(key, content, known.person, session.signature["at_utc"])
        register.record_signature(signed)
        session.signature.update(sha256=signed.sha256, ed25519=signed.signature)
        if session.path is not None:
            session.save()
    except BaseException:
        session.signature = before
        raise
    return signed


def carried_signature(session: ProcedureSession) -> Signed | None:
    """The key signature the session keeps (None: unsigned, or signed by name only)."""
    s = session.signature
    if not all(s.get(k) for k in ("who", "at_utc", "key_id", "sha256", "ed25519")):
        return None
    return Signed(s["sha256"], s["who"], s["key_id"], s["at_utc"], s["ed25519"])


def report_file_bytes(session: ProcedureSession, context: Mapping[str, Any] | None = None) -> bytes:
    """The report's HTML file: its canonical bytes, and its signature as the last line when the
    session is signed with a key (a session changed after signing no longer verifies)."""
    content = render_html(build_report(session, context)).encode("utf-8")
    signed = carried_signature(session)
    return with_block(content, signed) if signed is not None else content


def sign_report_file(
    register: Keys,
    session: ProcedureSession,
    who: str,
    key: Ed25519PrivateKey,
    output: str | Path,
    context: Mapping[str, Any] | None = None,
) -> Signed:
    """:func:`sign_session`, then the signed report written to ``output`` (whole or not at all;
    a target that cannot be written is refused before anything is signed)."""
    target = fileio.check_output_path(output)
    signed = sign_session(register, session, who, key, context)
    fileio.write_bytes(target, report_file_bytes(session, context))
    return signed


def sign_other_file(register: Keys, key: Ed25519PrivateKey, who: str, path: str | Path) -> Signed:
    """Sign a file that cannot carry its signature (the report's PDF): recorded in the register."""
    known = usable_key(register, key, who)
    signed = sign_bytes(key, fileio.read_bytes(path), known.person, clock.utc_iso())
    register.record_signature(signed, path)
    return signed
