"""The people's public signing keys and the report signatures made with them; whether a file is
the one that was signed. Append-only: a key is added once and never replaced; revoking it is a
fact of its own; a signature is a row of its own."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

from fha_studio import fileio
from fha_studio.logic.register import guard
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.history import History
from fha_studio.logic.register.records import utc_stamp
from fha_studio.logic.register.signing import Signed, signature_holds, split_block

#: What verify reads of a report at most (a report with its plots is a few MB).
_REPORT_LIMIT_BYTES = 256 * 1024 * 1024


@dataclass(frozen=True)
class SigningKey:
    """A person's public key as the register keeps it."""

    key_id: str
    person: str
    public_key: str  # 32 raw bytes, hex
    created_utc: str
    who: str
    revoked_utc: str = ""
    revoked_reason: str = ""


@dataclass(frozen=True)
class Verdict:
    """Whether a file is the one that was signed, and by whom (``reason`` says why not)."""

    valid: bool
    file: str
    sha256: str
    reason: str = ""
    signer: str = ""
    key_id: str = ""
    signed_utc: str = ""

    def as_dict(self) -> dict[str, object]:
        return {"valid": self.valid, "file": self.file, "signer": self.signer, "key_id": self.key_id,
                "signed_utc": self.signed_utc, "sha256": self.sha256, "reason": self.reason}


@guard.in_words
class Keys(History):
    """Signing keys and signatures."""

    @property
    def location(self) -> Path | str:
        """Where this register is, as :class:`~.store.Register` takes it: the file, or the
        server's URL."""
        return self._url or self.path

    def add_key(self, person: str, public_key_hex: str, key_id: str, who: str = "",
                at_utc: str | None = None) -> SigningKey:
        """A person's new public key (never replacing one: a key id already there is refused)."""
        person = person.strip()
        if not person:
            raise RegisterError("a signing key belongs to a person: give a name")
        if self.signing_key(key_id) is not None:
            raise RegisterError(f"signing key {key_id} is already in the register")
        created = utc_stamp(at_utc)
        with self._transaction() as db:
            db.execute(
                "INSERT INTO signing_key (key_id, person, public_key, created_utc, who)"
                " VALUES (?, ?, ?, ?, ?)",
                (key_id, person, public_key_hex, created, who))
        return SigningKey(key_id, person, public_key_hex, created, who)

    def revoke_key(self, key_id: str, reason: str = "", who: str = "", at_utc: str | None = None) -> None:
        """The key signs nothing from now on (its earlier signatures still verify)."""
        key = self.signing_key(key_id)
        if key is None:
            raise RegisterError(f"no signing key {key_id} in the register")
        if key.revoked_utc:
            raise RegisterError(f"signing key {key_id} was revoked at {key.revoked_utc}")
        with self._transaction() as db:
            db.execute("INSERT INTO key_revocation (key_id, at_utc, who, reason) VALUES (?, ?, ?, ?)",
                       (key_id, utc_stamp(at_utc), who, reason))

    def signing_keys(self, person: str | None = None) -> list[SigningKey]:
        """The keys (of one person), oldest first."""
        sql = ("SELECT k.*, r.at_utc AS revoked_utc, r.reason AS revoked_reason FROM signing_key k"
               " LEFT JOIN key_revocation r ON r.key_id = k.key_id")
        if person is not None:
            rows = self._db.execute(sql + " WHERE k.person = ? ORDER BY k.created_utc, k.key_id",
                                    (person.strip(),))
        else:
            rows = self._db.execute(sql + " ORDER BY k.person, k.created_utc, k.key_id")
        return [SigningKey(r["key_id"], r["person"], r["public_key"], r["created_utc"], r["who"],
                           r["revoked_utc"] or "", r["revoked_reason"] or "") for r in rows]

    def signing_key(self, key_id: str) -> SigningKey | None:
        return next((k for k in self.signing_keys() if k.key_id == key_id), None)

    def record_signature(self, signed: Signed, file: str | Path = "") -> None:
        """A signature made with a key of the register (checked here: a signature the register
        could not verify later is not recorded)."""
        key = self.signing_key(signed.key_id)
        if key is None:
            raise RegisterError(f"signing key {signed.key_id} is not in the register")
        if key.person != signed.signer:
            raise RegisterError(f"signing key {signed.key_id} is {key.person}'s, not {signed.signer}'s")
        if key.revoked_utc:
            raise RegisterError(f"signing key {signed.key_id} was revoked at {key.revoked_utc}")
        if not signature_holds(key.public_key, signed):
            raise RegisterError(f"the signature is not one of key {signed.key_id}")
        with self._transaction() as db:
            db.execute(
                "INSERT OR IGNORE INTO report_signature (signature, key_id, signer, signed_utc, sha256, file)"
                " VALUES (?, ?, ?, ?, ?, ?)",
                (signed.signature, signed.key_id, signed.signer, signed.signed_utc, signed.sha256,
                 str(Path(file).resolve()) if file else ""))

    def signatures_of(self, sha256: str) -> list[Signed]:
        rows = self._db.execute(
            "SELECT * FROM report_signature WHERE sha256 = ? ORDER BY signed_utc", (sha256,))
        return [Signed(r["sha256"], r["signer"], r["key_id"], r["signed_utc"], r["signature"]) for r in rows]

    def verify_file(self, path: str | Path) -> Verdict:
        """Whether the file at ``path`` is the one that was signed: by the signature it carries
        (an HTML report), else by a signature of its hash in the register (the PDF)."""
        shown = str(path)
        data = fileio.read_bytes(path, limit_bytes=_REPORT_LIMIT_BYTES)
        content, carried, damaged = split_block(data)
        digest = hashlib.sha256(content).hexdigest()
        if damaged:
            return Verdict(False, shown, digest, f"{shown}: {damaged}")
        if carried is None:
            known = self.signatures_of(digest)
            if not known:
                if not _looks_like_report(data):
                    return Verdict(False, shown, digest, f"{shown}: not a commissioning report of FHA Studio")
                return Verdict(False, shown, digest, f"{shown}: no signature: it carries none and the "
                               "register knows no signature of these bytes (changed since, or never signed)")
            carried = known[-1]
        return self._judge(shown, digest, carried)

    def _judge(self, shown: str, digest: str, signed: Signed) -> Verdict:
        def fails(why: str) -> Verdict:
            return Verdict(False, shown, digest, f"{shown}: {why}", signed.signer, signed.key_id,
                           signed.signed_utc)

        key = self.signing_key(signed.key_id)
        if key is None:
            return fails(f"signed with key {signed.key_id}, which this register does not know")
        if key.person != signed.signer:
            return fails(f"says it is signed by {signed.signer}, but key {signed.key_id} is {key.person}'s")
        if not signature_holds(key.public_key, signed):
            return fails(f"the signature is not {key.person}'s (key {key.key_id}): "
                         "the signature line was changed")
        if digest != signed.sha256:
            return fails(f"changed since it was signed: its SHA-256 is {digest}, "
                         f"the signed one {signed.sha256}")
        if key.revoked_utc and key.revoked_utc <= _stamp_or_text(signed.signed_utc):
            return fails(f"signed at {signed.signed_utc} with key {key.key_id}, revoked at {key.revoked_utc}")
        return Verdict(True, shown, digest, "", signed.signer, signed.key_id, signed.signed_utc)


def _looks_like_report(data: bytes) -> bool:
    head = data[:4096]
    return (b"<html" in head and b"Commissioning report" in head) or head.startswith(b"%PDF-")


def _stamp_or_text(when: str) -> str:
    """A signature's time as the register stamps times (comparable as text); as it is when it
    is no time (then the signature does not hold anyway)."""
    try:
        return utc_stamp(when)
    except RegisterError:
        return when
