"""The Procedures page's sign step with the person's own key (Ed25519): the key in the user's
keys folder whose public key the register keeps, its passphrase asked in a dialog; a person
without a key signs by name only, as the page says. The key stays loaded for this page's
session, so the PDF written after signing is signed too (found in the register by its hash)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.procedures.report import SignError, sign
from fha_studio.logic.register import Register, register_location
from fha_studio.logic.register.report_signing import (
    carried_signature,
    private_key_file_for,
    sign_other_file,
    sign_session,
)
from fha_studio.logic.register.signing import key_file_encrypted, load_private_key

#: asks the passphrase of a key file; None: the person cancelled
AskPassphrase = Callable[[Path], "str | None"]


class ReportSigner:
    """Signs a session's report with the signer's key when the register has one."""

    def __init__(self, register: Callable[[], Path | str | None] = lambda: None) -> None:
        #: the register with the keys, a file or a server's URL: the machine window's; None:
        #: $FHA_STUDIO_REGISTER, else the user's register file
        self.register = register
        self._key: Ed25519PrivateKey | None = None
        self._who = ""

    def _where(self) -> Path | str:
        return register_location(self.register())

    def sign(self, session: ProcedureSession, who: str, context: Mapping[str, Any] | None,
             ask: AskPassphrase) -> str:
        """Sign; returns what the message line says. SignError, RegisterError or SigningError
        (one line) when it is refused; the session is then as it was."""
        self.forget()
        where = self._where()
        if isinstance(where, Path) and not where.exists():
            sign(session, who, context)
            return f"Signed by {who.strip()} by name only (no register keeps a key of theirs)."
        with Register(where, create=False) as reg:
            key_file = private_key_file_for(reg, who)
            if key_file is None:
                sign(session, who, context)
                return (f"Signed by {who.strip()} by name only: the register has no key of theirs "
                        "(fha-studio register keys add --name NAME makes one).")
            secret = ""
            if key_file_encrypted(key_file):
                asked = ask(key_file)
                if asked is None:
                    raise SignError("not signed: the key's passphrase was not given")
                secret = asked
            key = load_private_key(key_file, secret)
            signed = sign_session(reg, session, who, key, context)
        self._key, self._who = key, signed.signer
        return (f"Signed by {signed.signer} with key {signed.key_id}; "
                "fha-studio register verify REPORT checks a copy.")

    def sign_pdf(self, session: ProcedureSession, pdf: Path) -> bool:
        """Sign the PDF written from the signed session (True) with the key loaded when signing."""
        signed = carried_signature(session)
        if self._key is None or signed is None or signed.signer != self._who:
            return False
        with Register(self._where(), create=False) as reg:
            sign_other_file(reg, self._key, self._who, pdf)
        return True

    def forget(self) -> None:
        """Drop the loaded key (a new session, another signer)."""
        self._key, self._who = None, ""
