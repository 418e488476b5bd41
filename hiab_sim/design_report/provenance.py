"""Where a result comes from: study and machine files, versions, git commit, solver settings, dates."""

from __future__ import annotations

import datetime as dt
import hashlib
import shutil
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from hiab_sim.design_report.page import section, table
from hiab_sim.results.schema import RESULT_FILE, Result
from hiab_sim.yaml_fields import parse_yaml

PACKAGES = ("hiab-sim", "numpy", "scipy", "mujoco", "dm-control", "casadi")


def package_version(name: str) -> str:
    """The installed version of a distribution, or "not installed"."""
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def git_commit(folder: Path) -> str:
    """The commit of the checkout ``folder`` lies in (noting uncommitted changes), or why there is none."""
    git = shutil.which("git")
    if git is None:
        return "unknown (git is not installed)"
    head = subprocess.run([git, "-C", str(folder), "rev-parse", "HEAD"], capture_output=True, text=True, check=False)
    if head.returncode != 0:
        return "unknown (not a git checkout)"
    status = subprocess.run(
        [git, "-C", str(folder), "status", "--porcelain", "--untracked-files=no"],
        capture_output=True,
        text=True,
        check=False,
    )
    return head.stdout.strip() + (" + uncommitted changes" if status.stdout.strip() else "")


def _file_line(path: Path) -> str:
    if not path.is_file():
        return f"{path} (no longer there)"
    return f"{path} (SHA-256 {hashlib.sha256(path.read_bytes()).hexdigest()[:16]})"


def study_emla(result: Result) -> str:
    """The EMLA set the study file names (``default`` when it names none), or why it is unknown."""
    path = Path(result.study)
    if not path.is_file():
        return "unknown (the study file is no longer there)"
    data = parse_yaml(path.read_text())
    return str(data.get("emla") or "default") if isinstance(data, dict) else "unknown"


def provenance(result: Result, folder: Path) -> str:
    """The provenance table."""
    s, sol = result.settings, result.solver
    made = dt.datetime.fromtimestamp((folder / RESULT_FILE).stat().st_mtime, tz=dt.UTC)
    machine = result.crane if result.crane_source is None else f"{result.crane} (copy of {result.crane_source})"
    rows = [
        ("study file", _file_line(Path(result.study))),
        ("machine file", machine),
        ("EMLA set", study_emla(result)),
        ("result folder", str(folder.resolve())),
        ("run written", made.strftime("%Y-%m-%d %H:%M UTC")),
        ("report written", dt.datetime.now(tz=dt.UTC).strftime("%Y-%m-%d %H:%M UTC")),
        ("git commit", git_commit(Path(__file__).resolve().parent)),
        ("versions", ", ".join(f"{p} {package_version(p)}" for p in PACKAGES)),
        ("solver", f"{sol.method}, inverse dynamics {sol.id_path}, re-check {result.recheck.id_path}"),
        (
            "discretisation",
            f"{s.spline_control_points} control points of degree {s.spline_degree}; {s.collocation_points} collocation "
            f"points every {s.collocation_step_s:g} s; {s.fine_grid_points} fine-grid points",
        ),
        (
            "tracking bands",
            f"{1e3 * s.tracking_bands.position_m:g} mm, {1e3 * s.tracking_bands.velocity_m_per_s:g} mm/s, "
            f"{s.tracking_bands.acceleration_m_per_s2:g} m/s² (held at {s.tracking_bands.collocation_fraction:g} of "
            "the band at the collocation points)",
        ),
        ("bounds [m]", f"low {list(s.xi_low)}, up {list(s.xi_up)}; envelope margin {s.envelope_margin:g}"),
        ("redundancy", s.redundancy),
    ]
    return section("Provenance", table(("item", "value"), rows))
