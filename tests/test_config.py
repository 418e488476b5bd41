"""Crane description: loading, body placement, scaling rule and every bad-input case."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import crane_from_dict, load_crane
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import shipped

RAW = yaml.safe_load(shipped("crane", "xs031").read_text())


def test_preset_keeps_every_source_mass(crane: Crane) -> None:
    """The 11 published bodies and their total mass (1062.93 kg) are all there."""
    published = [
        307.29601379,
        25.52660174,
        54.58702836,
        17.36281648,
        10.34519231,
        33.92850233,
        17.36281648,
        10.34519231,
        9.26136143,
        6.73059863,
        570.18877059,
    ]
    assert len(crane.bodies) == 11
    assert sum(b.mass for b in crane.bodies) == pytest.approx(sum(published), abs=1e-9)


def test_lift_boom_b_is_placed_through_the_tilt_pivot_frame(crane: Crane) -> None:
    """A com given in {Bc2} is moved into the lift boom frame {B11} by the {B11}->{Bc2} pose."""
    body = next(b for b in crane.bodies if b.name == "lift_boom_b")
    alpha2 = 0.24548563270531
    r = np.array([0.37610632101293 + 0.098495302558553, 0.01838181329939])
    com_source = np.array([0.54319901, 0.10543875])
    rot = np.array([[math.cos(alpha2), -math.sin(alpha2)], [math.sin(alpha2), math.cos(alpha2)]])
    np.testing.assert_allclose(body.com[:2], r + rot @ com_source, atol=1e-12)
    assert body.link == "lift_boom"
    assert body.inertia[2][2] == pytest.approx(5.97255351)


def test_bodies_scale_with_cylinder_and_rod_lengths(crane: Crane) -> None:
    """Doubling Lc doubles rod mass and com, keeps mass * x_com^2 / I_transverse fixed."""
    default = crane.default_lengths
    longer = LinkLengths(ChainLengths(default.lift.L, default.lift.Lc0, 2 * default.lift.Lc), default.tilt)
    before = {b.name: b for b in crane.bodies_for(default)}
    after = {b.name: b for b in crane.bodies_for(longer)}
    assert after["lift_rod"].mass == pytest.approx(2 * before["lift_rod"].mass)
    assert after["lift_rod"].com[0] == pytest.approx(2 * before["lift_rod"].com[0])
    assert after["lift_rod"].inertia[2][2] == pytest.approx(8 * before["lift_rod"].inertia[2][2])
    assert after["lift_rod"].inertia[0][0] == pytest.approx(2 * before["lift_rod"].inertia[0][0])
    factor = (2 * default.lift.Lc + default.lift.Lc0) / default.lift.x0
    assert after["lift_cylinder"].mass == pytest.approx(factor * before["lift_cylinder"].mass)
    assert after["tilt_rod"] == before["tilt_rod"]
    assert after["end_mass"] == before["end_mass"]


@pytest.mark.parametrize(
    ("key", "value"),
    [("L", 0.0), ("Lc0", -0.1), ("Lc", float("nan")), ("L", float("inf"))],
)
def test_non_positive_or_nan_length_names_the_field(crane: Crane, key: str, value: float) -> None:
    """Non-positive, NaN or infinite lengths raise InvalidInputError naming chain and key."""
    xi = {"L": 1.0071227324212, "Lc0": 0.085, "Lc": 0.745, key: value}
    lengths = LinkLengths(ChainLengths(**xi), crane.default_lengths.tilt)
    with pytest.raises(InvalidInputError, match=rf"lift\.{key} = .* must be a finite length > 0"):
        check_lengths(crane, lengths)


def test_stroke_longer_than_rod_is_rejected(crane: Crane) -> None:
    """Stroke outside [0, Lc] (const_j) names the stroke and the allowed interval."""
    lengths = LinkLengths(crane.default_lengths.lift, ChainLengths(1.132185817991, 0.3, 0.5))
    with pytest.raises(InvalidInputError, match=r"tilt\.stroke = 0\.59 m .* \[0, Lc\] = \[0, 0\.5\]"):
        check_lengths(crane, lengths)


def test_chain_longer_than_upper_links_in_working_stroke_is_rejected(crane: Crane) -> None:
    """Lc0 + x + Lc > L + L1 in the working range (const_k) names the joint range."""
    lengths = LinkLengths(ChainLengths(1.0071227324212, 0.2, 0.745), crane.default_lengths.tilt)
    with pytest.raises(InvalidInputError, match=r"lift\.joint_range = .* must lie in \["):
        check_lengths(crane, lengths)


def test_joint_sample_at_flat_triangle_is_rejected(crane: Crane) -> None:
    """Theta with sin q = 0 (k of eq. k1_3 undefined) is rejected with the reachable range."""
    chain = crane.lift
    with pytest.raises(InvalidInputError, match=r"theta1 = 2\.0735.* rad is out of range: must lie in \[-0\.161"):
        mechanism.check_joint_samples(chain, chain.default_lengths, np.array([0.5, chain.joint_offset]), "theta1")


def test_nan_joint_sample_is_rejected(crane: Crane) -> None:
    """NaN joint samples are rejected before any trigonometry."""
    with pytest.raises(InvalidInputError, match="theta2"):
        mechanism.check_joint_samples(crane.tilt, crane.tilt.default_lengths, np.array([np.nan]), "theta2")


def _mutated(path: list[str], value: object = None, delete: bool = False) -> dict:
    data = copy.deepcopy(RAW)
    node = data
    for key in path[:-1]:
        node = node[key]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return data


def test_unknown_yaml_key_is_rejected() -> None:
    """An unknown key names where it is and what is allowed."""
    with pytest.raises(ConfigError, match=r"chains\.lift: unknown key\(s\) \['Lcc'\]"):
        crane_from_dict(_mutated(["chains", "lift", "Lcc"], 0.7))


def test_missing_yaml_key_is_rejected() -> None:
    """A missing key is named."""
    with pytest.raises(ConfigError, match=r"chains\.tilt: missing key\(s\) \['stroke'\]"):
        crane_from_dict(_mutated(["chains", "tilt", "stroke"], delete=True))


def test_negative_body_mass_is_rejected() -> None:
    """A body mass <= 0 names the body and the bound."""
    with pytest.raises(InvalidInputError, match=r"bodies\.end_mass\.mass = -1 kg is out of range: must be > 0"):
        crane_from_dict(_mutated(["bodies", "end_mass", "mass"], -1.0))


def test_yaml_length_violating_triangle_is_rejected() -> None:
    """A crane file whose default lengths break const_k fails to load, naming the chain."""
    with pytest.raises(InvalidInputError, match=r"lift\.joint_range"):
        crane_from_dict(_mutated(["chains", "lift", "Lc0"], 0.3))


def test_unknown_preset_is_a_config_error() -> None:
    """A crane that is neither a preset nor a file gives a ConfigError naming the presets."""
    with pytest.raises(ConfigError, match="xs031"):
        load_crane("no-such-crane")


@pytest.mark.e2e
def test_cli_bad_crane_file_exits_2_without_traceback(tmp_path: Path) -> None:
    """The CLI prints the named-field message and exits with status 2, no traceback."""
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(_mutated(["chains", "tilt", "L"], -2.0)))
    result = subprocess.run(
        [sys.executable, "-m", "hiab_sim", "crane", "--crane", str(bad)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    assert "tilt.L = -2 m is out of range" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.e2e
def test_cli_help_lists_subcommands_and_version() -> None:
    """--help lists every subcommand; --version prints the package version."""
    result = subprocess.run([sys.executable, "-m", "hiab_sim", "--help"], capture_output=True, text=True, check=True)
    for name in ("crane", "mjcf", "validate", "emla-map", "optimize", "render", "compare"):
        assert name in result.stdout
    version = subprocess.run(
        [sys.executable, "-m", "hiab_sim", "--version"], capture_output=True, text=True, check=True
    )
    assert version.stdout.startswith("hiab-sim ")


def test_cli_reports_missing_osmesa_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """MUJOCO_GL=osmesa without libOSMesa: MuJoCo subcommands exit 2 with the install hint."""
    from hiab_sim import _gl
    from hiab_sim.cli import main

    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    monkeypatch.setattr(_gl.ctypes.util, "find_library", lambda name: None)
    assert main(["mjcf", "-o", "unused.xml"]) == 2
    err = capsys.readouterr().err
    assert "apt-get install libosmesa6" in err and err.count("\n") == 1


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_a_file_number_is_kept_as_written_up_to_the_magnitude_limit(value: float) -> None:
    """Any finite number within +-1e15 is read as it is; a larger one is refused naming the field."""
    from hiab_sim.yaml_fields import MAGNITUDE_LIMIT, number

    if abs(value) <= MAGNITUDE_LIMIT:
        assert number(value, "links.boom.bodies.boom.mass") == value
    else:
        with pytest.raises(InvalidInputError, match=r"links\.boom\.bodies\.boom\.mass .* magnitude <= 1e\+15"):
            number(value, "links.boom.bodies.boom.mass")
