"""The built wheel carries every shipped file: installed into a fresh environment, the CLI works from any folder."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import venv
from pathlib import Path

import mujoco
import numpy
import pytest

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e

REPO = Path(__file__).resolve().parents[1]
#: What the wheel is built from (the tracked sources; no .venv, runs/ or build/ from this checkout).
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "hiab_sim", "assets", "optimize", "validate")


def test_pyproject_lists_every_package_below_hiab_sim() -> None:
    """Every folder of hiab_sim/ with an __init__.py is a listed package, so the wheel cannot miss one."""
    listed = set(tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    on_disk = {".".join(p.parent.relative_to(REPO).parts) for p in (REPO / "hiab_sim").rglob("__init__.py")}
    assert on_disk <= listed, f"add to [tool.setuptools] packages: {sorted(on_disk - listed)}"


def test_wheel_installed_in_a_fresh_environment_optimizes_and_writes_mjcf(tmp_path: Path) -> None:
    """Built, installed with --no-deps into a new venv and run outside the repository: optimize and mjcf succeed.

    About 20 s on 2 cores (build 4 s, install 4 s, the default optimisation 6 s): not ``slow``.
    """
    source = tmp_path / "src"
    source.mkdir()
    for name in SOURCES:
        copy = shutil.copytree if (REPO / name).is_dir() else shutil.copy2
        kwargs = {"ignore": shutil.ignore_patterns("__pycache__", "*.pyc")} if (REPO / name).is_dir() else {}
        copy(REPO / name, source / name, **kwargs)
    dist = tmp_path / "dist"
    pip = [sys.executable, "-m", "pip"]
    subprocess.run([*pip, "wheel", "--no-deps", "-q", "-w", str(dist), str(source)], check=True, capture_output=True)
    wheel = next(dist.glob("hiab_sim-*.whl"))

    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    site = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    # The heavy dependencies come from this interpreter's site-packages (no download).
    shared = {str(Path(m.__file__).resolve().parent.parent) for m in (numpy, mujoco)}
    shared.add(sysconfig.get_paths()["purelib"])
    (Path(site) / "_deps.pth").write_text("\n".join(sorted(shared)) + "\n")
    subprocess.run(
        [*pip, "--python", str(python), "install", "--no-deps", "-q", str(wheel)],
        check=True,
        capture_output=True,
        text=True,
    )

    work = tmp_path / "elsewhere"
    work.mkdir()
    environment = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "osmesa"), "PYTHONPATH": ""}
    where = subprocess.run(
        [str(python), "-c", "import hiab_sim; print(hiab_sim.__file__)"],
        cwd=work,
        env=environment,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    assert where.startswith(str(env_dir)), where
    # A shipped study whose crane and EMLA files sit next to it resolves them inside the installed package.
    seed = subprocess.run(
        [
            str(python),
            "-c",
            "from hiab_sim.study.spec.study_file import load_study; print(load_study('seed_scale_spiral').path)",
        ],
        cwd=work,
        env=environment,
        check=False,
        capture_output=True,
        text=True,
    )
    assert seed.returncode == 0 and seed.stdout.startswith(str(env_dir)), seed.stderr
    cli = str(env_dir / "bin" / "hiab-sim")
    optimized = subprocess.run(
        [cli, "optimize", "--no-video", "--no-figures", "--quiet", "--out", "out"],
        cwd=work,
        env=environment,
        check=False,
        capture_output=True,
        text=True,
    )
    assert optimized.returncode == 0, optimized.stderr
    assert (work / "out" / "result.json").is_file()
    model = subprocess.run(
        [cli, "mjcf", "-o", "crane.xml"], cwd=work, env=environment, check=False, capture_output=True, text=True
    )
    assert model.returncode == 0, model.stderr
    assert "<mujoco" in (work / "crane.xml").read_text()
