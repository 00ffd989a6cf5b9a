"""Signing a commissioning report with a person's key: the HTML file carries its signature, the
register records it (the PDF, which cannot carry one, is found in the register by its hash).

The report's HTML is reproducible from the session, so the signature is made once, when the
person signs, and kept in the session file; every report written from that session carries it.
Nothing is half-done: the key is checked against the register before anything is written; the
register's record comes before the session file (a failure on the way leaves the session
unsigned, as it was).

A window on a register on a server asks the server from another thread: :class:`KnownKeys` holds
a person's keys as the server gave them, :func:`session_signature` and :func:`file_signature`
make a signature without recording it (the session unchanged), and the window records it
(``record_signature``) before it keeps it in the session."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Protocol

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


class KeyRecords(Protocol):
    """What signing asks a register of the keys (a :class:`Keys`, or :class:`KnownKeys`)."""

    def signing_keys(self, person: str | None = None) -> list[SigningKey]: ...

    def signing_key(self, key_id: str) -> SigningKey | None: ...


class KnownKeys:
    """A person's keys as the register gave them (asked once, by another thread): answers as the
    register would about them."""

    def __init__(self, keys: Iterable[SigningKey]):
        self._keys = list(keys)

    def signing_keys(self, person: str | None = None) -> list[SigningKey]:
        return [k for k in self._keys if person is None or k.person == person.strip()]

    def signing_key(self, key_id: str) -> SigningKey | None:
        return next((k for k in self._keys if k.key_id == key_id), None)


def usable_key(register: KeyRecords, key: Ed25519PrivateKey, person: str) -> SigningKey:
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


def private_key_file_for(register: KeyRecords, person: str) -> Path | None:
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
    signed, entry = session_signature(register, session, who, key, context)
    register.record_signature(signed)
    keep_signature(session, entry)
    return signed


def session_signature(
    register: KeyRecords,
    session: ProcedureSession,
    who: str,
    key: Ed25519PrivateKey,
    context: Mapping[str, Any] | None = None,
) -> tuple[Signed, dict[str, Any]]:
    """The signature of the session's report as ``who`` with ``key``, and the session's
    signature entry that carries it, neither recorded nor kept (the session is as it was).
    SignError while checks are open; RegisterError when the key is not ``who``'s usable key."""
    known = usable_key(register, key, who)
    before = dict(session.signature)
    try:
        sign(session, who, context, key_id=known.key_id, save=False)
        content = render_html(build_report(session, context)).encode("utf-8")
        signed = sign_bytes(key, content, known.person, session.signature["at_utc"])
        entry = {**session.signature, "sha256": signed.sha256, "ed25519": signed.signature}
    finally:
        session.signature = before
    return signed, entry


def keep_signature(session: ProcedureSession, entry: Mapping[str, Any]) -> None:
    """The session carries the signature (its file saved)."""
    session.signature = dict(entry)
    if session.path is not None:
        session.save()


def still_signs(session: ProcedureSession, entry: Mapping[str, Any], context: Mapping[str, Any] | None,
                signed: Signed) -> bool:
    """Whether ``signed`` (made by :func:`session_signature`) still covers the session's report
    with ``entry`` (a session changed since it was made does not)."""
    import hashlib

    before = dict(session.signature)
    session.signature = dict(entry)
    try:
        content = render_html(build_report(session, context)).encode("utf-8")
    finally:
        session.signature = before
    return hashlib.sha256(content).hexdigest() == signed.sha256


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
    signed = file_signature(register, key, who, path)
    register.record_signature(signed, path)
    return signed


def file_signature(register: KeyRecords, key: Ed25519PrivateKey, who: str, path: str | Path) -> Signed:
    """The signature of a file as ``who`` with ``key`` (their usable key), not recorded."""
    known = usable_key(register, key, who)
    return sign_bytes(key, fileio.read_bytes(path), known.person, clock.utc_iso())
