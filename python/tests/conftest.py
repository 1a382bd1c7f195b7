"""Shared fixtures: the command line to compare with, and short simulated scans."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def cli() -> list:
    """The Rust binary (MRTMAP_BIN, else target/debug or target/release's), else the wheel's
    command through the native module."""
    env = os.environ.get("MRTMAP_BIN")
    if env:
        return [env]
    for profile in ("debug", "release"):
        b = REPO / "target" / profile / "mrtmap"
        if b.exists():
            return [str(b)]
    return [sys.executable, "-m", "mrtmap"]


def mrtmap_cli(*args, check=True) -> subprocess.CompletedProcess:
    r = subprocess.run(cli() + [str(a) for a in args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"mrtmap {' '.join(map(str, args))} failed: {r.stderr}")
    return r


def simulate(out: Path, seed: int = 1, room: str = "office") -> Path:
    """A 20 s noise-free scan at 160×120 depth (a few seconds to simulate and to run)."""
    mrtmap_cli("simulate", "--room", room, "--out", out, "--seconds", 20, "--depth-size",
               "160x120", "--noise", "none", "--truth-rays", 1000, "--seed", seed)
    return out


@pytest.fixture(scope="session")
def scans(tmp_path_factory) -> list:
    """Three short scans of the office (seeds 1–3)."""
    base = tmp_path_factory.mktemp("scans")
    return [simulate(base / f"room-{k}", seed=k) for k in (1, 2, 3)]


@pytest.fixture
def fresh_copy(tmp_path):
    def copy(src: Path, name: str) -> Path:
        dst = tmp_path / name
        shutil.copytree(src, dst)
        return dst

    return copy
