"""The Procedures page's sign step with the person's own key (Ed25519): the key in the user's
keys folder whose public key the register keeps, its passphrase asked in a dialog; a person
without a key signs by name only, as the page says. The key stays loaded for this page's
session, so the PDF written after signing is signed too (found in the register by its hash).

A register on a server is asked through the window's register questions
(``gui/register_questions.py``), never on the GUI thread: the signer's keys first, then (the key
loaded and the signature made here) the signature recorded; only then does the session carry it.
The answer comes later: :meth:`ReportSigner.sign` returns None and ``done`` hears it."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.procedures.report import SignError, sign
from fha_studio.logic.register import Register, register_location
from fha_studio.logic.register.report_signing import (
    KnownKeys,
    carried_signature,
    file_signature,
    keep_signature,
    private_key_file_for,
    session_signature,
    sign_other_file,
    sign_session,
    still_signs,
)
from fha_studio.logic.register.server import is_server_url
from fha_studio.logic.register.signing import key_file_encrypted, load_private_key

if TYPE_CHECKING:
    from fha_studio.gui.register_questions import RegisterQuestions

#: asks the passphrase of a key file; None: the person cancelled
AskPassphrase = Callable[[Path], "str | None"]
#: hears how a signing asked of a server ended: what the message line says, and whether it signed
Done = Callable[[str, bool], None]


class ReportSigner:
    """Signs a session's report with the signer's key when the register has one."""

    def __init__(
        self,
        register: Callable[[], Path | str | None] = lambda: None,
        questions: Callable[[], RegisterQuestions | None] = lambda: None,
        say: Callable[[str], None] = lambda _text: None,
    ) -> None:
        """``register``: the register with the keys, a file or a server's URL: the window's;
        None: $FHA_STUDIO_REGISTER, else the user's register file. ``questions``: the window's
        questions of that register (a server's are asked from their own thread; None: asked
        here). ``say``: a line for the message line (a PDF's signature the server did not take)."""
        self.register = register
        self.questions = questions
        self.say = say
        self._key: Ed25519PrivateKey | None = None
        self._who = ""
        self._known: KnownKeys | None = None  # the signer's keys as a server gave them

    def _where(self) -> Path | str:
        return register_location(self.register())

    def _server_questions(self, where: Path | str) -> RegisterQuestions | None:
        questions = self.questions() if is_server_url(where) else None
        return questions if questions is not None and questions.on_server else None

    def sign(self, session: ProcedureSession, who: str, context: Mapping[str, Any] | None,
             ask: AskPassphrase, done: Done | None = None) -> str | None:
        """Sign; returns what the message line says. SignError, RegisterError or SigningError
        (one line) when it is refused; the session is then as it was. A register on a server:
        returns None at once, and ``done`` hears it once the server answered (or did not)."""
        self.forget()
        where = self._where()
        questions = self._server_questions(where)
        if questions is not None:
            self._sign_on_server(questions, session, who, context, ask, done or (lambda _said, _ok: None))
            return None
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

    def _sign_on_server(self, questions: RegisterQuestions, session: ProcedureSession, who: str,
                        context: Mapping[str, Any] | None, ask: AskPassphrase, done: Done) -> None:
        person = who.strip()

        def not_signed(why: str) -> None:
            done(f"Not signed: {why}.", False)

        def with_keys(keys: list[Any]) -> None:
            known = KnownKeys(keys)
            try:
                key_file = private_key_file_for(known, person)
                if key_file is None:
                    sign(session, who, context)
                    done(f"Signed by {person} by name only: the register has no key of theirs "
                         "(fha-studio register keys add --name NAME makes one).", True)
                    return
                secret = ""
                if key_file_encrypted(key_file):
                    asked = ask(key_file)
                    if asked is None:
                        raise SignError("not signed: the key's passphrase was not given")
                    secret = asked
                key = load_private_key(key_file, secret)
                signed, entry = session_signature(known, session, who, key, context)
            except ValueError as exc:  # open checks, a key not on this computer, a wrong passphrase
                done(str(exc), False)
                return

            def recorded(_answer: Any) -> None:
                if not still_signs(session, entry, context, signed):
                    not_signed("the session changed while the server was asked; sign again")
                    return
                keep_signature(session, entry)
                self._key, self._who, self._known = key, signed.signer, known
                done(f"Signed by {signed.signer} with key {signed.key_id}; "
                     "fha-studio register verify REPORT checks a copy.", True)

            questions.ask(f"the signature of {person}", lambda reg: reg.record_signature(signed),
                          recorded, not_signed)

        questions.ask(f"the signing keys of {person}", lambda reg: reg.signing_keys(person), with_keys,
                      not_signed)

    def sign_pdf(self, session: ProcedureSession, pdf: Path) -> bool:
        """Sign the PDF written from the signed session (True) with the key loaded when signing
        (a register on a server records it from another thread; one that does not take it is
        said)."""
        signed = carried_signature(session)
        if self._key is None or signed is None or signed.signer != self._who:
            return False
        where = self._where()
        questions = self._server_questions(where)
        if questions is not None and self._known is not None:
            made = file_signature(self._known, self._key, self._who, pdf)
            questions.ask(f"the signature of {pdf.name}", lambda reg: reg.record_signature(made, pdf),
                          lambda _answer: None,
                          lambda why: self.say(f"The PDF's signature was not recorded: {why}."))
            return True
        with Register(where, create=False) as reg:
            sign_other_file(reg, self._key, self._who, pdf)
        return True

    def forget(self) -> None:
        """Drop the loaded key (a new session, another signer)."""
        self._key, self._who, self._known = None, "", None
