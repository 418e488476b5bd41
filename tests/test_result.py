"""The typed result (study/result.py, study/codec.py): JSON round trips, older files, named errors."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import LinkLengths
from hiab_sim.errors import ConfigError
from hiab_sim.results.codec import from_json, optional, to_json
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import SCHEMA_VERSION, PlaybackView, Result

# Link lengths inside a crane's range (LinkLengths may validate); every other field from its type hint.
st.register_type_strategy(
    LinkLengths, st.lists(st.floats(0.05, 2.0), min_size=6, max_size=6).map(LinkLengths.from_array)
)
json_scalars = st.none() | st.booleans() | st.integers(-1000, 1000) | st.floats(-1e6, 1e6) | st.text(max_size=8)
json_values = st.recursive(
    json_scalars,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner, max_size=3),
    max_leaves=8,
)
known = {f.name for f in fields(Result)}
results = st.builds(
    Result,
    schema_version=st.just(SCHEMA_VERSION),
    extra=st.dictionaries(st.text(min_size=1, max_size=8).filter(lambda k: k not in known), json_values, max_size=3),
)


def _text(result: Result) -> str:
    """result.json as written (NaN and inf written as JSON extensions, as json.dumps does)."""
    return json.dumps(result.to_json(), indent=2)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(results)
def test_any_result_survives_a_json_round_trip(result: Result) -> None:
    """Write -> parse -> from_json -> write gives the same text, and the same object where no NaN occurs."""
    text = _text(result)
    back = Result.from_json(json.loads(text))
    assert _text(back) == text
    if "NaN" not in text:
        assert back == result


def _minimal_result_json() -> dict[str, Any]:
    """A result.json of schema 1 as written before the typed result (no schema_version), built by hand."""
    lengths_json = {"lift": {"L": 1.0, "Lc0": 0.1, "Lc": 0.7}, "tilt": {"L": 1.1, "Lc0": 0.1, "Lc": 0.7}}
    energy = dict.fromkeys(("mechanical", "copper", "rotor_friction", "screw_viscous", "inertial", "electrical"), 1.0)
    worst = {"name": "row", "scaled_margin": 0.5}
    tracking = {"position_m": 1e-4, "velocity_m_per_s": 1e-3, "acceleration_m_per_s2": 1e-2, "telescope_m": 0.0}
    actuator = {
        "peak_force_N": 1e4,
        "peak_velocity_m_per_s": 0.1,
        "peak_electrical_power_W": 900.0,
        "min_envelope_margin": 0.2,
        "net_energy_J": 10.0,
        "drawn_energy_J": 12.0,
        "energy_J": energy,
    }
    design = {
        "lengths": lengths_json,
        "id_path": "analytic",
        "grid_points": 251,
        "cost_W2s": 5.0,
        "cost_note": "note",
        "net_electrical_energy_J": 10.0,
        "drawn_energy_without_regeneration_J": 12.0,
        "drawn_energy_sum_of_actuators_J": 14,  # an integer where a float is expected: accepted
        "energy_breakdown_J": energy,
        "actuators": {"lift": actuator},
        "max_violation": 0.0,
        "worst_constraint": worst,
        "tracking_error": tracking,
        "collocation_cost_W2s": 5.5,
        "collocation_max_violation": 0.0,
    }
    failed = {"lengths": "optimal", "trajectory": "initial", "evaluable": False, "error": "out of range"}
    data = {
        "crane": "xs031",
        "study": "s.yaml",
        "name": "s",
        "initial": design,
        "optimal": design,
        "improvement": {
            "cost_ratio": 0.9,
            "net_energy_saved_J": 1.0,
            "net_energy_saved_percent": 10.0,
            "decomposition": {
                "note": "n",
                "designs": {"optimal_lengths_initial_trajectory": failed},
                "from_lengths_J": None,
                "from_lengths_percent": None,
                "from_trajectory_J": 0.5,
                "from_trajectory_percent": 5.0,
                "interaction_J": None,
                "total_J": 1.0,
            },
        },
        "solver": {
            "method": "SLSQP",
            "id_path": "analytic",
            "success": True,
            "status": 0,
            "message": "ok",
            "iterations": 3,
            "wall_time_s": 0.1,
            "total_wall_time_s": 0.2,
            "max_violation_scaled": 0.0,
            "function_evaluations": 4,
            "gradient_evaluations": 3,
        },
        "recheck": {
            "id_path": "mujoco",
            "grid_points": 251,
            "note": "n",
            "max_violation_scaled": 0.0,
            "worst_constraint": worst,
            "tracking_error": tracking,
            "net_electrical_energy_J": 10.0,
            "initial_max_violation_scaled": 0.0,
            "force_difference_between_paths_N": 1e-9,
        },
        "multistart": {
            "starts": [
                {
                    "start": 0,
                    "initial_lengths": lengths_json,
                    "optimal_lengths": None,
                    "cost_W2s": None,
                    "success": False,
                    "message": "Iteration limit reached",
                    "iterations": 1,
                }
            ],
            "tolerance_m": 1e-4,
            "converged_starts": 0,
            "same_optimum": False,
            "distinct_optima": [],
            "failed_starts": [{"start": 0, "initial_xi": [1.0, 0.1, 0.7, 1.1, 0.1, 0.7], "message": "m"}],
        },
        "settings": {
            "spline_control_points": 16,
            "spline_degree": 5,
            "collocation_points": 26,
            "collocation_step_s": 0.25,
            "fine_grid_points": 251,
            "redundancy": "r",
            "tracking_bands": {
                "position_m": 1e-3,
                "velocity_m_per_s": 1e-2,
                "acceleration_m_per_s2": 0.1,
                "collocation_fraction": 0.5,
            },
            "xi_low": [0.8, 0.04, 0.6, 0.9, 0.04, 0.6],
            "xi_up": [1.25, 0.3, 1.0, 1.35, 0.3, 1.0],
            "envelope_margin": 0.0,
            "payload_kg": 150,
        },
        "history": [
            {"iteration": 0, "cost": 5.0, "scaled_cost": 1.0, "max_violation": 0.0, "xi": [1.0] * 6, "wall_time": 0.0}
        ],
    }
    return json.loads(json.dumps(data))  # no shared sub-dicts


def test_a_file_written_before_schema_version_reads_as_schema_1_and_writes_back_every_key() -> None:
    """A schema-1 file without schema_version loads; written back: the same values under schema 2's names."""
    data = _minimal_result_json()
    result = Result.from_json(data)
    assert result.schema_version == 2 and result.crane_source is None and result.extra == {}
    assert result.optimal.lengths == LinkLengths.from_array([1.0, 0.1, 0.7, 1.1, 0.1, 0.7])
    assert result.improvement.decomposition.designs["optimal_lengths_initial_trajectory"].evaluable is False
    assert result.multistart.starts[0].optimal_lengths is None
    written = result.to_json()
    assert next(iter(written)) == "schema_version" and written.pop("schema_version") == 2
    renamed = json.loads(
        json.dumps(data)
        .replace("drawn_energy_without_regeneration_J", "drawn_energy_summed_drives_J")
        .replace("drawn_energy_sum_of_actuators_J", "drawn_energy_per_drive_sum_J")
    )
    assert written == renamed  # 14 == 14.0 and 150 == 150.0: the same numbers


def test_unknown_top_level_keys_are_kept_and_written_back() -> None:
    """A section of a newer writer (e.g. a later issue's) is kept in extra and round-trips."""
    data = {**_minimal_result_json(), "schema_version": 1, "future_section": {"energy_J": [[1.0, 2.0]]}}
    result = Result.from_json(data)
    assert result.extra == {"future_section": {"energy_J": [[1.0, 2.0]]}}
    again = result.to_json()
    assert Result.from_json(again).to_json() == again


def test_a_newer_schema_is_refused_by_name() -> None:
    """A result.json of a later, incompatible layout is a ConfigError naming both versions."""
    with pytest.raises(ConfigError, match=f"schema_version {SCHEMA_VERSION + 1}; this hiab-sim reads up to"):
        Result.from_json({**_minimal_result_json(), "schema_version": SCHEMA_VERSION + 1})


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda d: d["optimal"]["lengths"]["tilt"].pop("Lc"), "missing 'optimal.lengths.tilt.Lc'"),
        (lambda d: d["solver"].update(success="yes"), "'solver.success' must be true or false"),
        (lambda d: d["settings"].update(xi_low=0.8), "'settings.xi_low' must be a list"),
        (lambda d: d["history"][0].update(iteration=1.5), "'history[0].iteration' must be an integer"),
        (
            lambda d: d["initial"]["actuators"]["lift"].update(net_energy_J="10"),
            "'initial.actuators.lift.net_energy_J'",
        ),
        (lambda d: d.update(recheck=[]), "'recheck' must be a mapping"),
    ],
)
def test_a_missing_or_mistyped_key_is_named_with_its_path(tmp_path: Path, damage: Any, message: str) -> None:
    """read_result names the file and the dotted path of the first bad key (ConfigError, one line)."""
    data = _minimal_result_json()
    damage(data)
    (tmp_path / "result.json").write_text(json.dumps(data))
    with pytest.raises(ConfigError, match=re.escape(message)) as info:
        read_result(tmp_path)
    assert str(info.value).startswith(str(tmp_path / "result.json")) and "\n" not in str(info.value)


def test_the_renderer_view_needs_only_the_crane_and_both_designs_lengths() -> None:
    """PlaybackView reads the renderer's contract and ignores every other key."""
    data = _minimal_result_json()
    view = PlaybackView.from_json({k: data[k] for k in ("crane", "initial", "optimal")})
    assert view.crane == "xs031" and view.initial.lengths == Result.from_json(data).initial.lengths
    with pytest.raises(ConfigError, match=re.escape("missing 'initial.lengths'")):
        PlaybackView.from_json({"crane": "xs031", "initial": {}, "optimal": {}})


@pytest.mark.parametrize(("duty", "period"), [(None, "cycle"), ({"cycles_per_hour": 60}, "duty period")])
def test_the_renderer_view_names_the_period_its_battery_energy_covers(duty: object, period: str) -> None:
    """A battery energy with a duty model covers the duty period (cycle and rest), one without it the cycle."""
    data = _minimal_result_json()
    figure = {"battery_energy_J": 1.0} | ({} if duty is None else {"duty": duty})
    view = PlaybackView.from_json(
        {k: data[k] for k in ("crane", "initial", "optimal")} | {"energy": {"initial": figure, "optimal": figure}}
    )
    assert view.energy is not None and view.energy.period == period


@dataclass(frozen=True)
class _Section:
    """A section a later version adds."""

    value: float
    matrix: tuple[tuple[float, ...], ...] = ()


@dataclass(frozen=True)
class _Old:
    name: str


@dataclass(frozen=True)
class _New:
    name: str
    section: _Section | None = optional()


def test_an_optional_section_is_absent_until_set_and_older_files_still_load() -> None:
    """A field made with optional() is left out while None, and a file without it loads with None."""
    old = to_json(_Old("a"))
    assert from_json(_New, old) == _New("a")
    assert to_json(_New("a")) == old == {"name": "a"}
    assert to_json(_New("a", _Section(2))) == {"name": "a", "section": {"value": 2.0, "matrix": []}}
    assert from_json(_New, {"name": "a", "section": {"value": 2}}) == _New("a", _Section(2.0))
    matrix = _New("a", _Section(1.0, ((1.0, 2.0), (3.0, 4.0))))  # e.g. a cross-evaluation of designs x tasks
    assert from_json(_New, json.loads(json.dumps(to_json(matrix)))) == matrix


def test_numpy_values_are_written_as_plain_numbers() -> None:
    """np.float64 / np.int64 / np.bool_ values become JSON numbers and booleans, arrays nested lists."""
    out = to_json({"a": np.float64(1.5), "b": np.int64(3), "c": np.bool_(True), "d": (np.float32(0.5),)})
    assert json.dumps(out) == '{"a": 1.5, "b": 3, "c": true, "d": [0.5]}'
    assert to_json(np.arange(4.0).reshape(2, 2)) == [[0.0, 1.0], [2.0, 3.0]]


def test_a_replaced_optional_field_is_written_and_read_back() -> None:
    """An optional field set by replace (as run_study does for a copied crane) is written and read back.

    The original result still omits it.
    """
    result = Result.from_json(_minimal_result_json())
    moved = replace(result, crane="crane.yaml", crane_source="my_crane.yaml")
    back = Result.from_json(json.loads(json.dumps(moved.to_json())))
    assert back.crane == "crane.yaml" and back.crane_source == "my_crane.yaml"
    assert "crane_source" not in result.to_json()


def test_a_schema_1_file_loads_with_the_renamed_energy_keys() -> None:
    """Schema 1's two drawn-energy keys land under names that state their boundaries."""
    result = Result.from_json(_minimal_result_json())
    assert result.schema_version == 2
    assert result.initial.drawn_energy_summed_drives_J == 12.0
    assert result.initial.drawn_energy_per_drive_sum_J == 14.0
    written = result.to_json()
    assert "drawn_energy_without_regeneration_J" not in json.dumps(written)


def test_a_schema_2_file_with_either_set_of_old_names_reads_under_the_new_ones() -> None:
    """Files written as version 2 before both renamings met carry one set of old keys: each is renamed."""
    data = {**_minimal_result_json(), "schema_version": 2}
    result = Result.from_json(data)
    assert result.initial.drawn_energy_summed_drives_J == 12.0
    assert result.initial.drawn_energy_per_drive_sum_J == 14.0


def test_a_schema_1_sensitivity_of_a_battery_study_reads_with_its_keys_renamed_and_its_unit_joules() -> None:
    """Schema 1 stored the battery energy [J] as ``sensitivity.cost_W2s``: it reads as objective_value in J."""
    data = {
        **_minimal_result_json(),
        "energy": None,
        "sensitivity": {
            "cost_W2s": 5153.4,
            "active_tolerance": 1e-6,
            "kkt_residual": 2e-8,
            "multipliers": [
                {
                    "constraint": "tracking.position.y_tcp",
                    "multiplier": 1e-3,
                    "unit": "mm",
                    "cost_per_unit_W2s": 7.3,
                    "percent_per_unit": 0.142,
                    "rows": 10,
                }
            ],
        },
    }
    data.pop("energy")
    as_costf2 = Result.from_json(data).sensitivity
    assert as_costf2 is not None and as_costf2.objective == "costf2" and as_costf2.objective_unit == "W^2 s"
    data["energy"] = {"objective": "battery_energy"}
    from hiab_sim.results.schema import upgrade

    upgraded = upgrade(data)
    assert upgraded["schema_version"] == 2 and upgraded["sensitivity"]["objective_unit"] == "J"
    assert upgraded["sensitivity"]["objective_value"] == 5153.4
    assert upgraded["sensitivity"]["multipliers"][0]["objective_decrease_per_unit"] == 7.3
    assert "cost_W2s" not in upgraded["sensitivity"] and data["sensitivity"]["cost_W2s"] == 5153.4  # input untouched
