"""The tool's key pair: made once, kept private, published as a JWKS that verifies our JWTs."""

from __future__ import annotations

import stat
from pathlib import Path

import jwt

from app.lti.keys import PRIVATE_KEY_FILE, ToolKeys


def test_the_key_is_made_once_private_and_keeps_its_kid(tmp_path: Path) -> None:
    folder = tmp_path / "keys"
    first = ToolKeys.load_or_create(folder)
    again = ToolKeys.load_or_create(folder)
    assert stat.S_IMODE((folder / PRIVATE_KEY_FILE).stat().st_mode) == 0o600
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert again.kid == first.kid
    assert again.public_jwks() == first.public_jwks()
    assert [p.name for p in folder.iterdir()] == [PRIVATE_KEY_FILE]  # no draft left behind


def test_a_key_made_elsewhere_has_another_kid(tmp_path: Path) -> None:
    assert (
        ToolKeys.load_or_create(tmp_path / "a").kid != ToolKeys.load_or_create(tmp_path / "b").kid
    )


def test_a_copied_key_readable_by_others_is_made_private_again(tmp_path: Path) -> None:
    keys = ToolKeys.load_or_create(tmp_path)
    (tmp_path / PRIVATE_KEY_FILE).chmod(0o644)
    assert ToolKeys.load_or_create(tmp_path).kid == keys.kid
    assert stat.S_IMODE((tmp_path / PRIVATE_KEY_FILE).stat().st_mode) == 0o600


def test_the_public_jwks_verifies_what_the_tool_signs(tmp_path: Path) -> None:
    keys = ToolKeys.load_or_create(tmp_path)
    token = keys.sign({"iss": "tool", "answer": 42})
    assert jwt.get_unverified_header(token)["kid"] == keys.kid
    published = jwt.PyJWKSet.from_dict(keys.public_jwks())[keys.kid]
    assert jwt.decode(token, published, algorithms=["RS256"])["answer"] == 42
    assert "d" not in keys.public_jwk()  # the private exponent never leaves
