"""The soil's force on the bucket tip along a reference, the shipped soils and the excavator's task CSVs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from script_helper import load_script

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine.dynamics.soil import SoilProperties, tool_force_world
from hiab_sim.machine.dynamics.soil_file import SOILS, load_soil, soil_from_mapping
from hiab_sim.machine.dynamics.soil_load import ONSET_DEPTH_M, ONSET_SPEED_M_S, smoothstep, soil_force_on_tcp

G = 9.81  # m/s^2, exact_excavator.yaml
OPTIMIZE = Path(__file__).resolve().parents[1] / "optimize"
CYCLES = load_script("make_excavator_cycles", OPTIMIZE / "make_excavator_cycles.py")
Y_GROUND = CYCLES.Y_GROUND  # m, exact_excavator.yaml notes.ground
WIDTH = CYCLES.BUCKET_WIDTH  # m, the bucket width the excavator's tasks assume
#: Published digging forces of a mini excavator of the eXact's class: Bobcat E20 (4,211 lb = 1.91 t),
#: bucket digging force 3,620 lbf and arm digging force 1,778 lbf (Bobcat's announcement of the E20 as
#: reported at heavy-equipment-rates.blogspot.com; the page writes "foot pounds" for these forces).
LBF = 4.4482216152605  # N
E20_BUCKET_FORCE = 3620.0 * LBF  # 16.1 kN
E20_ARM_FORCE = 1778.0 * LBF  # 7.91 kN: the arm's crowd, which drags the bucket through the cut


def _task(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(t, tip (T, 2), tcp_angle, tip velocity by central differences) of a shipped task CSV."""
    lines = (OPTIMIZE / name).read_text(encoding="utf-8").splitlines()
    rows = [line for line in lines if not line.startswith("#")]
    assert rows[0] == "t,x,y,tcp_angle"
    data = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    t, tip, theta = data[:, 0], data[:, 1:3], data[:, 3]
    return t, tip, theta, np.gradient(tip, t, axis=0)


def _force(soil: SoilProperties, tip: np.ndarray, velocity: np.ndarray, theta: np.ndarray) -> np.ndarray:
    return soil_force_on_tcp(tip, velocity, theta, y_ground=Y_GROUND, width_m=WIDTH, soil=soil, gravity=G)


@pytest.mark.parametrize("name", sorted(SOILS))
def test_no_force_above_the_ground_or_at_rest(name: str) -> None:
    """Tips above the ground (any velocity, any attitude) and tips at rest in the soil feel nothing."""
    soil = load_soil(name)
    rng = np.random.default_rng(3)
    above = np.column_stack([rng.uniform(1.0, 2.5, 200), Y_GROUND + rng.uniform(1e-6, 1.0, 200)])
    velocity = rng.normal(0.0, 0.5, (200, 2))
    theta = rng.uniform(-np.pi, 0.0, 200)
    assert np.all(_force(soil, above, velocity, theta) == 0.0)
    below = above - [0.0, 1.1]
    assert np.all(_force(soil, below, np.zeros((200, 2)), theta) == 0.0)


@pytest.mark.parametrize("name", sorted(SOILS))
@pytest.mark.parametrize("rake_deg", [40.0, 60.0, 80.0])
def test_a_steady_horizontal_cut_is_the_earthmoving_equation(name: str, rake_deg: float) -> None:
    """Deeper than the onset and faster than it, the force is soil.py's; the mirrored cut gives the mirrored force.

    Travelling towards the machine (-x) with the hinge behind and above the tip at rake alpha, the
    hinge -> tip vector points at theta = alpha - pi; travelling away (+x), at theta = -alpha.
    """
    soil = load_soil(name)
    alpha, depth = np.radians(rake_deg), 0.1
    tip = np.array([[1.8, Y_GROUND - depth]] * 3)
    towards = _force(soil, tip, np.tile([-0.3, 0.0], (3, 1)), np.full(3, alpha - np.pi))
    expected = tool_force_world(soil, G, alpha, depth, WIDTH, -1.0)[0]
    np.testing.assert_allclose(towards, np.tile(expected, (3, 1)), rtol=1e-12)
    assert depth > ONSET_DEPTH_M and 0.3 > ONSET_SPEED_M_S
    away = _force(soil, tip, np.tile([0.3, 0.0], (3, 1)), np.full(3, -alpha))
    np.testing.assert_allclose(away, towards * [-1.0, 1.0], rtol=1e-12)


@pytest.mark.parametrize("csv", ["exact_digging_cycle.csv", "exact_grading_pass.csv"])
@pytest.mark.parametrize("name", sorted(SOILS))
def test_the_force_opposes_the_horizontal_travel_along_the_tasks(csv: str, name: str) -> None:
    """Wherever the soil pushes the tip, its horizontal push is against the tip's horizontal travel."""
    _, tip, theta, velocity = _task(csv)
    force = _force(load_soil(name), tip, velocity, theta)
    cutting = np.linalg.norm(force, axis=1) > 0.0
    assert cutting.sum() > 50  # the task does cut
    assert np.all(force[cutting, 0] * velocity[cutting, 0] < 0.0)
    assert np.all(force[tip[:, 1] > Y_GROUND] == 0.0)


def test_the_digging_force_is_finite_steady_and_below_a_published_digging_force() -> None:
    """Along the digging CSV the drag's steady force is soil.py's at the cut's depth and rake, below breakout.

    The bound: the published arm digging force of a 1.9 t mini excavator (7.9 kN), below its bucket
    digging force (16.1 kN): a machine of this class can pull the cut.
    """
    _, tip, theta, velocity = _task("exact_digging_cycle.csv")
    for name in sorted(SOILS):
        soil = load_soil(name)
        magnitude = np.linalg.norm(_force(soil, tip, velocity, theta), axis=1)
        assert np.all(np.isfinite(magnitude))
        depth = Y_GROUND - tip[:, 1].min()
        steady = np.linalg.norm(tool_force_world(soil, G, np.radians(60.0), depth, WIDTH, -1.0)[0])
        np.testing.assert_allclose(magnitude.max(), steady, rtol=1e-4)  # CSV rounding: 10 urad
        assert 0.0 < magnitude.max() < E20_ARM_FORCE < E20_BUCKET_FORCE


def test_the_onset_blend_is_c2_and_reaches_one() -> None:
    """The quintic smoothstep: 0 and 1 at its ends with zero first and second derivatives (finite differences)."""
    h = 1e-4
    for end, value in ((0.0, 0.0), (1.0, 1.0)):
        s = smoothstep(np.array([end - h, end, end + h]))
        assert s[1] == value
        assert abs(s[2] - s[0]) / (2 * h) < 1e-6
        assert abs(s[2] - 2 * s[1] + s[0]) / h**2 < 1e-3
    assert np.all(np.diff(smoothstep(np.linspace(0.0, 1.0, 101))) > 0.0)


def test_a_cut_with_the_bucket_backwards_is_refused() -> None:
    """Travelling +x with the bucket set for a -x cut leaves no failure wedge in sand: refused, naming tcp_angle."""
    soil = load_soil("loose_sand")
    tip = np.array([[1.8, Y_GROUND - 0.1]])
    with pytest.raises(InvalidInputError, match="tcp_angle"):
        _force(soil, tip, np.array([[0.3, 0.0]]), np.array([np.radians(30.0) - np.pi]))
    with pytest.raises(InvalidInputError, match="width_m"):
        soil_force_on_tcp(tip, np.zeros((1, 2)), np.zeros(1), y_ground=Y_GROUND, width_m=0.0, soil=soil, gravity=G)
    with pytest.raises(InvalidInputError, match="velocity"):
        soil_force_on_tcp(tip, np.zeros((2, 2)), np.zeros(1), y_ground=Y_GROUND, width_m=WIDTH, soil=soil, gravity=G)


def test_soil_files_load_with_sources_and_refuse_bad_values_by_field() -> None:
    """Both shipped soils load; a bad value names its field, a value without a source or an unknown key is refused."""
    text = (Path(__file__).resolve().parents[1] / "hiab_sim" / "presets" / "soil_medium_clay.yaml").read_text()
    data = yaml.safe_load(text)
    clay = soil_from_mapping(data)
    assert clay == load_soil("medium_clay") and clay.cohesion_Pa == pytest.approx(35910.0)
    assert "medium clay" in clay.source and load_soil("loose_sand").friction_angle_rad == pytest.approx(np.radians(29))
    bad = {**data, "cohesion_Pa": {"value": -1.0, "source": "estimate: a test"}}
    with pytest.raises(InvalidInputError, match=r"soil\.cohesion_Pa"):
        soil_from_mapping(bad)
    with pytest.raises(ConfigError, match="adhesion_Pa"):
        soil_from_mapping({**data, "adhesion_Pa": 1000.0})
    with pytest.raises(ConfigError, match="unknown"):
        soil_from_mapping({**data, "colour": "brown"})
    with pytest.raises(ConfigError, match=r"soil 'no_such_soil': neither a shipped name \(loose_sand, medium_clay\)"):
        load_soil("no_such_soil")


def test_the_task_csvs_are_the_generator_output(tmp_path: Path) -> None:
    """optimize/exact_*.csv are exactly what optimize/make_excavator_cycles.py writes (deterministic)."""
    CYCLES.main(tmp_path)
    for name in ("exact_digging_cycle.csv", "exact_grading_pass.csv"):
        assert (tmp_path / name).read_bytes() == (OPTIMIZE / name).read_bytes()


@pytest.mark.parametrize("csv", ["exact_digging_cycle.csv", "exact_grading_pass.csv"])
def test_the_tasks_are_rest_to_rest_below_and_above_ground(csv: str) -> None:
    """Uniform 50 Hz times, the same pose at both ends with zero velocity, a cut below and a dump above ground."""
    t, tip, theta, velocity = _task(csv)
    np.testing.assert_allclose(np.diff(t), 0.02, atol=1e-9)
    np.testing.assert_array_equal(tip[0], tip[-1])
    assert theta[0] == theta[-1]
    np.testing.assert_allclose(velocity[[0, -1]], 0.0, atol=1e-12)
    depth = {"exact_digging_cycle.csv": CYCLES.CUT_DEPTH, "exact_grading_pass.csv": CYCLES.GRADE_DEPTH}[csv]
    assert Y_GROUND - tip[:, 1].min() == pytest.approx(depth, abs=1e-5)
