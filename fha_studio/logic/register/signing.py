"""A person's signing key (Ed25519) and a signed report: what is signed, where the signature
goes, and how a file is checked against it. No register here: :mod:`.keys` keeps the public keys.

A key's id is the first 16 hex digits of the SHA-256 of its raw public key. The private key is a
PKCS #8 PEM file of its own (mode 0600), encrypted with the person's passphrase when one is given.

What is signed is a statement (:func:`statement`): the SHA-256 of the report's exact bytes, the
signer, the key's id and the time, as canonical JSON; so neither the file nor who signed it nor
when can be changed without the signature failing. An HTML report carries its signature as the
last line of the file (:data:`BLOCK_MARKER`); the bytes before that line are the ones hashed. A
file that cannot carry one (the PDF) is found in the register by its hash.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fha_studio import fileio
from fha_studio.paths import user_data_dir

if TYPE_CHECKING:  # the library is imported where a key is made, read or used (a tenth of a second)
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

#: The statement's format: what a signature signs.
STATEMENT_FORMAT = "fha-report-signature/1"
#: The last line of a signed HTML report begins with this (after the canonical bytes' newline).
BLOCK_MARKER = b"\n<!-- " + STATEMENT_FORMAT.encode() + b" "
_BLOCK_END = b" -->\n"
#: A private key file is read up to this size (a PEM key is about 200 bytes).
_KEY_FILE_LIMIT_BYTES = 64 * 1024


class SigningError(ValueError):
    """A key or a signature cannot be used: one line naming what and where."""


def keys_dir() -> Path:
    """Where a person's private keys live by default: ``keys/`` in the user data directory."""
    return user_data_dir() / "keys"


def key_id_of(public_raw: bytes) -> str:
    """A public key's id: 16 hex digits of the SHA-256 of its 32 raw bytes."""
    return hashlib.sha256(public_raw).hexdigest()[:16]


def public_raw(key: Ed25519PrivateKey) -> bytes:
    from cryptography.hazmat.primitives import serialization

    return key.public_key().public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)


def new_key() -> Ed25519PrivateKey:
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    return Ed25519PrivateKey.generate()


def default_key_path(key_id: str) -> Path:
    return keys_dir() / f"{key_id}.pem"


def write_private_key(key: Ed25519PrivateKey, path: Path, passphrase: str = "") -> Path:
    """The private key as PEM at ``path``, mode 0600, encrypted when ``passphrase`` is given; an
    existing file is never overwritten (it may be someone's only key)."""
    from cryptography.hazmat.primitives import serialization

    if passphrase:
        encryption: serialization.KeySerializationEncryption = serialization.BestAvailableEncryption(
            passphrase.encode("utf-8"))
    else:
        encryption = serialization.NoEncryption()
    data = key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, encryption)
    if os.path.lexists(path):
        raise SigningError(f"key file {path}: already exists (a key is never replaced; choose another path)")
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except OSError as exc:
        raise SigningError(f"key file {path}: cannot write it: {fileio.os_reason(exc)}") from None
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        os.chmod(path, 0o600)
    except OSError as exc:
        path.unlink(missing_ok=True)
        raise SigningError(f"key file {path}: not written: {fileio.os_reason(exc)}") from None
    return path


def key_file_encrypted(path: Path) -> bool:
    """Whether the key file needs a passphrase (False also when it cannot be read: loading says why)."""
    try:
        return b"ENCRYPTED" in fileio.read_bytes(path, limit_bytes=_KEY_FILE_LIMIT_BYTES)
    except (fileio.FileProblem, OSError):
        return False


def load_private_key(path: Path, passphrase: str = "") -> Ed25519PrivateKey:
    """The private key in ``path``; SigningError when the file is missing, is no Ed25519 key, or
    the passphrase is missing or wrong."""
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

    try:
        info = os.stat(path)
    except OSError as exc:
        raise SigningError(f"key file {path}: {fileio.os_reason(exc)}") from None
    if not stat.S_ISREG(info.st_mode):
        raise SigningError(f"key file {path}: not a file")
    try:
        data = fileio.read_bytes(path, limit_bytes=_KEY_FILE_LIMIT_BYTES)
    except fileio.FileProblem as exc:
        raise SigningError(f"key file {exc}") from None
    encrypted = b"ENCRYPTED" in data
    if encrypted and not passphrase:
        raise SigningError(f"key file {path}: it is encrypted: give its passphrase")
    try:
        key = serialization.load_pem_private_key(
            data, password=passphrase.encode("utf-8") if encrypted else None)
    except Exception:  # ValueError/TypeError, or the Rust parser's own errors for damaged input
        if encrypted:
            # A wrong passphrase decrypts to garbage; about one time in 256 the garbage has valid
            # padding and fails as a damaged key instead of a bad password, so both say the same.
            raise SigningError(f"key file {path}: wrong passphrase (or the key file is damaged)") from None
        raise SigningError(f"key file {path}: not a private key (damaged, or not a PEM key file)") from None
    if not isinstance(key, Ed25519PrivateKey):
        raise SigningError(f"key file {path}: not an Ed25519 key")
    return key


@dataclass(frozen=True)
class Signed:
    """One signature: the statement's fields and the signature (hex)."""

    sha256: str
    signer: str
    key_id: str
    signed_utc: str
    signature: str

    def as_dict(self) -> dict[str, str]:
        return {"format": STATEMENT_FORMAT, "sha256": self.sha256, "signer": self.signer,
                "key_id": self.key_id, "signed_utc": self.signed_utc, "signature": self.signature}


def statement(sha256: str, signer: str, key_id: str, signed_utc: str) -> bytes:
    """What a signature signs: canonical JSON (sorted keys, no spaces, UTF-8)."""
    fields = {"format": STATEMENT_FORMAT, "sha256": sha256, "signer": signer, "key_id": key_id,
              "signed_utc": signed_utc}
    return json.dumps(fields, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode("utf-8")


def sign_bytes(key: Ed25519PrivateKey, content: bytes, signer: str, signed_utc: str) -> Signed:
    """Sign the SHA-256 of ``content`` as ``signer`` at ``signed_utc``."""
    digest = hashlib.sha256(content).hexdigest()
    key_id = key_id_of(public_raw(key))
    signature = key.sign(statement(digest, signer, key_id, signed_utc))
    return Signed(digest, signer, key_id, signed_utc, signature.hex())


def signature_holds(public_key_hex: str, signed: Signed) -> bool:
    """Whether ``signed.signature`` is the key's signature of its statement."""
    from cryptography.exceptions import InvalidSignature
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey

    try:
        public = Ed25519PublicKey.from_public_bytes(bytes.fromhex(public_key_hex))
        public.verify(bytes.fromhex(signed.signature),
                      statement(signed.sha256, signed.signer, signed.key_id, signed.signed_utc))
    except (InvalidSignature, ValueError):
        return False
    return True


def with_block(content: bytes, signed: Signed) -> bytes:
    """An HTML report's canonical bytes with its signature as the last line."""
    text = json.dumps(signed.as_dict(), sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return content + BLOCK_MARKER + text.encode("ascii") + _BLOCK_END


def split_block(data: bytes) -> tuple[bytes, Signed | None, str]:
    """(the canonical bytes, the signature carried, why none) of a file's bytes. Without a
    signature line: (data, None, ""); a line that is there but cannot be read: (data, None, why)."""
    at = data.rfind(BLOCK_MARKER)
    if at < 0:
        return data, None, ""
    tail = data[at + len(BLOCK_MARKER):]
    if not tail.endswith(_BLOCK_END):
        return data, None, "its signature line is damaged or has text after it"
    try:
        fields: Any = json.loads(tail[: -len(_BLOCK_END)].decode("ascii"))
        signed = Signed(*(str(fields[k]) for k in ("sha256", "signer", "key_id", "signed_utc", "signature")))
        if fields.get("format") != STATEMENT_FORMAT:
            raise ValueError
    except (ValueError, KeyError, TypeError, AttributeError, UnicodeDecodeError):
        return data, None, "its signature line is damaged"
    return data[:at], signed, ""
