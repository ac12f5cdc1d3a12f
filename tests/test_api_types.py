"""The dashboard's API types (frontend/src/api/schema.d.ts) are generated from the server's OpenAPI
schema and committed; this fails when the server's models changed without `make api-types`."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

FRONTEND = Path(__file__).resolve().parents[1] / "frontend"


@pytest.mark.skipif(shutil.which("node") is None, reason="needs Node.js")
@pytest.mark.skipif(not (FRONTEND / "node_modules").is_dir(), reason="needs frontend/node_modules: run `make frontend`")
def test_the_committed_api_types_match_the_servers_schema() -> None:
    result = subprocess.run(
        ["node", "scripts/gen-api.mjs", "--check"],
        cwd=FRONTEND,
        env={"PATH": str(Path(sys.executable).parent) + ":/usr/bin:/bin", "PYTHON": sys.executable},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr + result.stdout
