"""`horde serve`: its options, the URLs it prints and its warning about exposed hosts."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import pytest

from horde.server import cli_serve
from horde.server.cli_serve import add_serve_parser, serve, settings_from_args, urls
from horde.server.logs import log_config


def parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="horde")
    add_serve_parser(parser.add_subparsers(dest="command"))
    return parser.parse_args(argv)


def test_defaults_and_overrides(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("HORDE_PORT", raising=False)
    monkeypatch.delenv("HORDE_HOST", raising=False)
    monkeypatch.delenv("HORDE_VISER_PORT", raising=False)
    args = parse(["serve"])
    assert args.handler is serve
    settings = settings_from_args(args)
    assert (settings.host, settings.port) == ("127.0.0.1", 8000)
    settings = settings_from_args(parse(["serve", "--host", "::1", "--port", "9001", "--data", str(tmp_path)]))
    assert (settings.host, settings.port, settings.data) == ("::1", 9001, tmp_path)
    assert urls(settings) == {
        "Dashboard": "http://[::1]:9001/",
        "API": "http://[::1]:9001/api",
        "API docs": "http://[::1]:9001/docs",
    }
    assert settings.viser_port == 8080, "serve starts the live view on 8080 by default"
    assert settings_from_args(parse(["serve", "--viser-port", "9100"])).viser_port == 9100
    assert settings_from_args(parse(["serve", "--no-view"])).viser_port is None


def test_serve_prints_its_urls_and_warns_when_exposed(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    monkeypatch.delenv("HORDE_TOKEN", raising=False)
    calls: list[dict[str, Any]] = []
    monkeypatch.setattr("uvicorn.run", lambda app, **kwargs: calls.append(kwargs))
    assert serve(parse(["serve", "--port", "9002", "--data", str(tmp_path)])) == 0
    out = capsys.readouterr()
    assert "http://127.0.0.1:9002/api" in out.out and "http://127.0.0.1:9002/docs" in out.out
    assert "Dashboard: http://127.0.0.1:9002/" in out.out
    assert "WARNING" not in out.err
    assert calls == [{"host": "127.0.0.1", "port": 9002, "log_level": "info", "log_config": log_config(),
                      "ws_per_message_deflate": False, "timeout_keep_alive": 75}]  # fmt: skip

    # Beyond loopback without a token: refused, unless asked for on purpose (then a warning).
    calls.clear()
    assert serve(parse(["serve", "--host", "0.0.0.0", "--data", str(tmp_path)])) == 2
    assert "refusing to start" in capsys.readouterr().err and calls == []
    assert serve(parse(["serve", "--host", "0.0.0.0", "--allow-open", "--data", str(tmp_path)])) == 0
    assert "WARNING" in capsys.readouterr().err and len(calls) == 1
    monkeypatch.setenv("HORDE_ALLOW_OPEN", "1")
    assert serve(parse(["serve", "--host", "0.0.0.0", "--data", str(tmp_path)])) == 0
    assert "WARNING" in capsys.readouterr().err
    monkeypatch.delenv("HORDE_ALLOW_OPEN")
    monkeypatch.setenv("HORDE_TOKEN", "secret")
    assert serve(parse(["serve", "--host", "0.0.0.0", "--data", str(tmp_path)])) == 0
    assert "WARNING" not in capsys.readouterr().err
    assert cli_serve.security_warning(settings_from_args(parse(["serve"]))) is None


def test_horde_cli_has_serve() -> None:
    from horde.cli import build_parser

    args = build_parser().parse_args(["serve", "--port", "9003"])
    assert args.port == 9003
