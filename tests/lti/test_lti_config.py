"""`ros2-classroom lti config`: the values a teacher pastes into the LMS."""

from __future__ import annotations

import json
import stat
from pathlib import Path

from app.lti.keys import PRIVATE_KEY_FILE, ToolKeys
from tests.conftest import run_cli

BASE = "https://hub.example.edu/services/classroom"


def test_lti_config_prints_the_urls_and_the_public_key(tmp_path: Path) -> None:
    keys_dir, lti_dir = tmp_path / "keys", tmp_path / "lti"
    result = run_cli(
        "lti", "config", "--base-url", BASE + "/", "--keys-dir", str(keys_dir),
        "--lti-dir", str(lti_dir),
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    out = result.stdout
    for line in (
        f"Login initiation URL:       {BASE}/lti/login",
        f"Launch (redirect) URL:      {BASE}/lti/launch",
        f"Deep-linking URL:           {BASE}/lti/deep-link",
        f"Public keyset (JWKS) URL:   {BASE}/lti/jwks",
        f"Initiate login URL          {BASE}/lti/login",  # Moodle's field
        f"Tool Keyset URL             {BASE}/lti/jwks",  # Open edX's field
    ):
        assert line in out
    # The key was made once, private, and the JWKS printed is that key's.
    assert stat.S_IMODE((keys_dir / PRIVATE_KEY_FILE).stat().st_mode) == 0o600
    keys = ToolKeys.load_or_create(keys_dir)
    printed = json.loads(out[out.index('{\n  "keys"') :].split("\n}\n")[0] + "\n}")
    assert printed == keys.public_jwks()
    canvas = json.loads(out[out.index('{\n  "title"') :].split("\n}\n")[0] + "\n}")
    assert canvas["oidc_initiation_url"] == f"{BASE}/lti/login"
    assert canvas["public_jwk_url"] == f"{BASE}/lti/jwks"
    assert {p["target_link_uri"] for p in canvas["extensions"][0]["settings"]["placements"]} == {
        f"{BASE}/lti/deep-link"
    }
    # Dynamic registration: the URL carries this deployment's registration key, kept private.
    key = (lti_dir / "registration-key").read_text().strip()
    assert f"Registration URL:           {BASE}/lti/register?key={key}" in out
    assert stat.S_IMODE((lti_dir / "registration-key").stat().st_mode) == 0o600
    again = run_cli(
        "lti", "config", "--base-url", BASE, "--keys-dir", str(keys_dir), "--lti-dir", str(lti_dir)
    )
    assert f"Key id (kid):               {keys.kid}" in again.stdout  # the same key, kept
    assert f"?key={key}" in again.stdout


def test_lti_config_refuses_plain_http_to_another_host(tmp_path: Path) -> None:
    result = run_cli(
        "lti", "config", "--base-url", "http://hub.example.edu", "--keys-dir", str(tmp_path)
    )
    assert result.returncode == 2
    assert "LMSes only talk to LTI tools over https" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / PRIVATE_KEY_FILE).exists()
