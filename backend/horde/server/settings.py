"""The server's settings, one BaseSettings read from HORDE_* environment variables."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Literal

from pydantic import Field, SecretStr, field_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from horde.runs.run_setup import Limits
from horde.server.hosts import HostRule


class Settings(BaseSettings):
    """Where the server keeps its data, who may change it, where it listens, and how much it holds.

    Every field reads the environment variable HORDE_<FIELD> (HORDE_DATA, HORDE_TOKEN, HORDE_PORT, ...).
    """

    model_config = SettingsConfigDict(env_prefix="HORDE_", extra="ignore")

    data: Path = Field(default=Path(".horde"), description="data directory: the SQLite store lives here")
    token: SecretStr | None = Field(default=None, description="when set, mutating requests need 'Bearer <token>'")
    host: str = Field(default="127.0.0.1", description="address to bind (loopback by default)")
    port: int = Field(default=8000, ge=0, le=65535)
    viser_port: int | None = Field(
        default=None, ge=0, le=65535, description="port of the viser live view (None: no live view; serve uses 8080)"
    )
    frontend: Path | None = Field(
        default=None, description="the built dashboard (default: the repository's frontend/dist)"
    )
    scenarios: Path | None = Field(default=None, description="scenario folder (default: the repository's)")
    max_runs: int = Field(default=32, ge=1, le=1000)
    max_worlds: int = Field(default=256, ge=1, le=100_000)
    max_demons: int = Field(default=10_000, ge=1, le=10_000)
    max_weights: int = Field(default=12_000_000, ge=1, le=100_000_000)  # scenarios/nexting.toml: 10.4 M
    history: int = Field(default=10_000, ge=16, le=1_000_000, description="rows of each run's history buffer")
    history_every: int = Field(default=1, ge=1, le=1_000_000, description="steps between history rows, at least")
    history_interval: float = Field(
        default=0.005, ge=0.0, le=60.0, description="seconds between history rows, at least (a full-speed run samples)"
    )
    evaluation_seconds: float = Field(
        default=30.0, gt=0.0, le=3600.0, description="seconds a Monte-Carlo evaluation may run (422 beyond)"
    )
    snapshot_every: float = Field(
        default=2.0,
        gt=0.0,
        le=3600.0,
        description="seconds between snapshots of a running run: a hard kill loses at most about this much learning",
    )
    switch_interval: float = Field(
        default=0.001, gt=0.0, le=0.1, description="sys.setswitchinterval of the server process (seconds)"
    )
    stream_rate: float = Field(default=30.0, gt=0.0, le=120.0, description="stream messages per second per client")
    max_body: int = Field(
        default=1024 * 1024, ge=1024, le=2**31, description="bytes of a request body at most (413 beyond)"
    )
    max_import_body: int = Field(
        default=256 * 1024 * 1024,
        ge=1024,
        le=2**33,
        description="bytes of a snapshot import (POST /api/runs/import, POST /api/streams/import)",
    )
    allow_open: bool = Field(
        default=False, description="bind beyond loopback without HORDE_TOKEN (anyone who reaches it may change runs)"
    )
    allowed_hosts: list[str] = Field(
        default_factory=list,
        description="names besides loopback and HORDE_HOST that requests may give in Host (DNS rebinding guard); "
        "'*' allows any",
    )
    origins: list[str] = Field(
        default_factory=list,
        description="extra browser origins allowed to open WebSockets (besides the server's own), e.g. a dev server",
    )
    worker_stall_seconds: float = Field(
        default=30.0,
        gt=0.0,
        le=3600.0,
        description="a worker whose main loop has not moved for this long is reported (its run's message, its events)"
        " and commands for it give up",
    )
    test_hooks: bool = Field(
        default=False, description="tests only: workers obey a crash command (a segfault, an abort, a hang)"
    )
    study_executor: Literal["ray", "local"] = Field(
        default="ray", description="where study tasks run: Ray (this machine, or ray_address), or one by one here"
    )
    ray_address: str | None = Field(default=None, description="a Ray cluster to join (HORDE_RAY_ADDRESS)")
    run_workers: Literal["auto", "process", "ray"] = Field(
        default="auto",
        description="where live runs, stream runs and protocol jobs learn: processes of this machine, or actors of "
        "the Ray cluster at ray_address; auto: Ray when ray_address is set",
    )
    ray_run_cpus: float = Field(default=1.0, gt=0.0, le=1024.0, description="CPUs a run's actor asks of the cluster")
    study_workers: int | None = Field(default=None, ge=1, le=4096, description="CPUs of the local Ray (default all)")

    @field_validator("token", mode="before")
    @classmethod
    def _empty_is_none(cls, value: object) -> object:
        return None if value == "" else value

    def runs_on_ray(self) -> bool:
        """Whether runs learn on the Ray cluster at `ray_address`."""
        return self.run_workers == "ray" or (self.run_workers == "auto" and self.ray_address is not None)

    def limits(self) -> Limits:
        """The run limits: every field of `Limits` that a setting of the same name sets (the rest keep defaults)."""
        names = [f.name for f in dataclasses.fields(Limits) if f.name in type(self).model_fields]
        return Limits(**{name: getattr(self, name) for name in names})

    def host_rule(self) -> HostRule:
        """The names requests may give in `Host`: loopback, `host`, `allowed_hosts` (see hosts.py)."""
        return HostRule.of(self.host, self.allowed_hosts)

    def is_loopback(self) -> bool:
        """Whether `host` only listens on this machine."""
        return self.host_rule().loopback_only
