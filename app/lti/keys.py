"""The tool's own RSA key pair: made once, kept in a folder only the service reads.

The private key signs our client assertions and deep-linking responses; the
public half is what the LMS is given (pasted or fetched as a JWKS). Its
``kid`` is the key's RFC 7638 thumbprint, so it never changes for one key and
a new key (a rotation) gets a new one by itself.
"""

from __future__ import annotations

import base64
import hashlib
import json
import logging
import os
import stat
from collections.abc import Mapping
from pathlib import Path

import jwt
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric import rsa

from app import PROJECT_ROOT

DEFAULT_DIR = PROJECT_ROOT / "var" / "lti" / "keys"
PRIVATE_KEY_FILE = "tool-private-key.pem"
KEY_BITS = 2048  # the minimum LTI's security framework asks for, and what LMSes expect
ALGORITHM = "RS256"

log = logging.getLogger(__name__)


def _b64url_uint(value: int) -> str:
    raw = value.to_bytes((value.bit_length() + 7) // 8, "big")
    return base64.urlsafe_b64encode(raw).rstrip(b"=").decode("ascii")


def _new_private_pem() -> bytes:
    key = rsa.generate_private_key(public_exponent=65537, key_size=KEY_BITS)
    return key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    )


def _create_once(path: Path) -> None:
    """Write a new key unless one exists; two processes racing still end with one key."""
    draft = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    fd = os.open(draft, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(_new_private_pem())
            out.flush()
            os.fsync(out.fileno())
        try:
            os.link(draft, path)  # fails if another process got there first: keep theirs
        except FileExistsError:
            pass
    finally:
        draft.unlink(missing_ok=True)


class ToolKeys:
    """The tool's signing key and its public JWKS."""

    def __init__(self, private_key: rsa.RSAPrivateKey) -> None:
        self._private = private_key
        numbers = private_key.public_key().public_numbers()
        self._public_jwk = {
            "e": _b64url_uint(numbers.e),
            "kty": "RSA",
            "n": _b64url_uint(numbers.n),
        }
        canonical = json.dumps(self._public_jwk, separators=(",", ":"), sort_keys=True)
        digest = hashlib.sha256(canonical.encode("ascii")).digest()
        self.kid = base64.urlsafe_b64encode(digest).rstrip(b"=").decode("ascii")

    @classmethod
    def load_or_create(cls, folder: Path) -> ToolKeys:
        """The key in ``folder``, made on first use (folder 0700, key file 0600)."""
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        path = folder / PRIVATE_KEY_FILE
        if not path.exists():
            _create_once(path)
        mode = stat.S_IMODE(path.stat().st_mode)
        if mode & 0o077:
            # A copied or restored key may have lost its mode; only its owner may read it.
            log.warning("%s was readable by others (mode %o); set it to 0600", path, mode)
            path.chmod(0o600)
        key = serialization.load_pem_private_key(path.read_bytes(), password=None)
        if not isinstance(key, rsa.RSAPrivateKey):
            raise ValueError(f"{path} holds no RSA private key")
        return cls(key)

    def public_jwk(self) -> dict[str, str]:
        return {**self._public_jwk, "kid": self.kid, "alg": ALGORITHM, "use": "sig"}

    def public_jwks(self) -> dict[str, list[dict[str, str]]]:
        return {"keys": [self.public_jwk()]}

    def sign(self, claims: Mapping[str, object]) -> str:
        """A compact JWT of ``claims``, RS256, with our ``kid`` so the platform finds the key."""
        return jwt.encode(
            dict(claims), self._private, algorithm=ALGORITHM, headers={"kid": self.kid}
        )
