"""``trajectory.npz`` follows its declared schema: what a run writes, what the reader accepts and refuses."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.errors import ConfigError
from hiab_sim.results.trajectory_file import (
    SCHEMA_VERSION,
    TRAJECTORY_FILE,
    VERSION_KEY,
    declared_keys,
    read_trajectory,
    write_trajectory,
)


def _arrays(samples: int = 5) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(0)
    out = {key: rng.normal(size=(samples, 3)) for key in declared_keys()}
    out["time"] = np.linspace(0.0, 1.0, samples)
    return out


def test_written_file_round_trips_every_declared_array_with_its_version(tmp_path: Path) -> None:
    """Write then read: the same arrays bit for bit, and the schema version."""
    arrays = _arrays()
    write_trajectory(tmp_path, arrays)
    back = read_trajectory(tmp_path)
    assert back.version == SCHEMA_VERSION
    for key, value in arrays.items():
        np.testing.assert_array_equal(back.get(key), value)


def test_writer_refuses_arrays_that_lack_a_declared_key(tmp_path: Path) -> None:
    """A writer that forgets a declared array fails before a file exists."""
    arrays = _arrays()
    del arrays["optimal_electrical_power"]
    with pytest.raises(ValueError, match="optimal_electrical_power"):
        write_trajectory(tmp_path, arrays)
    assert not (tmp_path / TRAJECTORY_FILE).exists()


def _raw(tmp_path: Path, **arrays: np.ndarray) -> Path:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)  # type: ignore[arg-type]
    (tmp_path / TRAJECTORY_FILE).write_bytes(buffer.getvalue())
    return tmp_path


def test_a_file_from_before_the_schema_reads_as_version_0(tmp_path: Path) -> None:
    """No ``schema_version``: version 0 with the same keys (files written by earlier releases)."""
    assert read_trajectory(_raw(tmp_path, **_arrays())).version == 0


def test_a_newer_schema_version_is_refused_naming_both(tmp_path: Path) -> None:
    """A file of a later schema is one ConfigError line naming its version and ours."""
    arrays = {**_arrays(), VERSION_KEY: np.array(SCHEMA_VERSION + 1)}
    with pytest.raises(ConfigError, match=f"{SCHEMA_VERSION + 1} is newer .*{SCHEMA_VERSION}"):
        read_trajectory(_raw(tmp_path, **arrays))


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("optimal_position", np.full((5, 3), np.nan), "NaN"),
        ("optimal_position", np.zeros((4, 3)), "4 rows"),
        ("time", np.array([0.0, 0.5, 0.4, 0.8, 1.0]), "increasing"),
    ],
)
def test_a_broken_array_is_named_in_one_line(tmp_path: Path, key: str, value: np.ndarray, message: str) -> None:
    """NaN, a wrong number of rows, a time axis that goes back: one line naming the array."""
    trajectory = read_trajectory(_raw(tmp_path, **{**_arrays(), key: value}))
    with pytest.raises(ConfigError, match=message) as error:
        trajectory.time() if key == "time" else trajectory.design("optimal", "position")
    assert "\n" not in str(error.value)


def test_not_an_npz_is_one_line(tmp_path: Path) -> None:
    """A corrupt file: ConfigError naming it."""
    (tmp_path / TRAJECTORY_FILE).write_text("not a zip")
    with pytest.raises(ConfigError, match=r"not a valid \.npz"):
        read_trajectory(tmp_path)


@pytest.mark.e2e
def test_a_run_writes_exactly_the_declared_arrays(tmp_path: Path) -> None:
    """A single-task optimisation's trajectory.npz holds the declared keys, its version, and nothing else."""
    from test_study_small import small_study

    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import study_from_dict

    run_study(study_from_dict(small_study(), "small.yaml"), tmp_path / "run", progress=None, figures=False)
    trajectory = read_trajectory(tmp_path / "run")
    assert trajectory.version == SCHEMA_VERSION
    assert set(trajectory.arrays) == set(declared_keys())
