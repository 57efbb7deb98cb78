"""Shared fixtures: the repository's examples and the CLI binary the Python results are
compared with (WORMWEAR_CLI, else target/debug/wormwear or target/release/wormwear)."""

import os
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def cli_path() -> pathlib.Path:
    given = os.environ.get("WORMWEAR_CLI")
    if given:
        return pathlib.Path(given)
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "wormwear"
        if p.is_file():
            return p
    found = shutil.which("wormwear")
    if found:
        return pathlib.Path(found)
    pytest.fail("no wormwear binary: build it (cargo build -p wormwear-cli) or set WORMWEAR_CLI")


@pytest.fixture(scope="session")
def cli():
    path = cli_path()

    def run(*args, check=True):
        out = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True)
        if check and out.returncode != 0:
            raise AssertionError(f"wormwear {' '.join(map(str, args))}: {out.stderr}")
        return out

    return run


@pytest.fixture(scope="session")
def design_file():
    return EXAMPLES / "gear-1x40-design.toml"


@pytest.fixture(scope="session")
def fast_gear_file(tmp_path_factory):
    """The design example made fast for sweeps: no bending, 6 positions, a coarse grid."""
    import wormwear

    g = wormwear.load(EXAMPLES / "gear-1x40-design.toml").with_(
        **{
            "bending.model": "none",
            "analysis.positions": 6,
            "analysis.flank_cells_height": 20,
            "analysis.flank_cells_face": 30,
        }
    )
    path = tmp_path_factory.mktemp("fast") / "fast.toml"
    path.write_text(g.to_toml())
    return path
