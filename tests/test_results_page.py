"""The results pages: each is what its committed run data render, data hold only declared fields, the tolerances.

Whether the data are current against fresh runs is tests/test_results_data.py (the studies CI can
afford) and, for the long studies, the comparison with tests/data/shipped_optima.json below.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
from script_helper import load_script

from hiab_sim.docs_site.results_data import (
    SECTIONS,
    RunData,
    differences,
    load_data,
    pick,
    select,
)
from hiab_sim.docs_site.results_page import BLOCKS, block_names, pages, render_page, stale_pages

ROOT = Path(__file__).resolve().parents[1]
#: The studies too long for CI to re-run (minutes each): their data are held to the recorded optima.
LONG_STUDIES = ("xs031_codesign", "xs031_duty_mix", "exact_digging", "exact_grading", "exact_duty_mix")
DATA = load_data()


def test_every_results_page_is_what_its_data_render() -> None:
    """No page under docs/results/ differs from what docs/results/data renders (run: results_page render)."""
    assert [p.name for p in stale_pages(RunData(DATA))] == []


def test_every_generated_block_on_the_pages_has_its_generator_and_every_generator_a_block() -> None:
    """The markers name known blocks, and no generator is left without a page that shows it."""
    names = [name for page in pages() for name in block_names(page.read_text())]
    assert len(names) == len(set(names))
    assert set(names) == set(BLOCKS)


def test_rendering_replaces_only_the_text_between_the_markers() -> None:
    """A hand-written line around a block survives; a stale number inside one is rewritten."""
    page = (ROOT / "docs" / "results" / "default-study.md").read_text()
    start = page.index("<!-- results:default-designs:start -->")
    tampered = page[:start] + "Hand-written line.\n" + page[start:].replace("| optimal |", "| optimal, stale |", 1)
    rendered = render_page(tampered, RunData(DATA))
    assert "Hand-written line.\n<!-- results:default-designs:start -->" in rendered
    assert rendered.replace("Hand-written line.\n", "") == page


def _leaves(tree: Any, path: str = "") -> dict[str, Any]:
    """Every leaf of a JSON tree by its dotted path (written apart from the selector to check it)."""
    if isinstance(tree, dict):
        return {k: v for key, sub in tree.items() for k, v in _leaves(sub, f"{path}.{key}" if path else key).items()}
    if isinstance(tree, list):
        return {k: v for i, sub in enumerate(tree) for k, v in _leaves(sub, f"{path}.{i}").items()}
    return {path: tree}


def _declared(path: str, fields: tuple[str, ...]) -> bool:
    steps = path.split(".")
    for field in fields:
        want = field.split(".")
        if len(steps) >= len(want) and all(w in ("*", s) for w, s in zip(want, steps, strict=False)):
            return True
    return False


@pytest.mark.parametrize("study", sorted(DATA))
def test_committed_data_hold_only_declared_fields(study: str) -> None:
    """Every number in docs/results/data/<study>.json sits under a declared field, and picking again changes nothing."""
    data = DATA[study]
    assert data and set(data) <= set(SECTIONS)
    for section, tree in data.items():
        fields = SECTIONS[section][2]
        leaves = _leaves(tree)
        assert all(_declared(path, fields) for path in leaves), [p for p in leaves if not _declared(p, fields)]
        assert pick(tree, fields) == tree


def test_a_selector_copies_the_values_at_their_paths() -> None:
    """``*`` steps over keys and items; an absent path selects nothing; the shape is the source's."""
    tree = {"a": {"x": {"v": 1.0, "w": 2}, "y": {"v": 3.0}}, "b": [{"v": 4}, {"v": 5, "u": 6}], "c": None}
    assert select(tree, "a.*.v") == {"a": {"x": {"v": 1.0}, "y": {"v": 3.0}}}
    assert select(tree, "b.*.v") == {"b": [{"v": 4}, {"v": 5}]}
    assert select(tree, "c.v") is None and select(tree, "d") is None
    assert pick(tree, ("a.x.w", "b.*.u")) == {"a": {"x": {"w": 2}}, "b": [None, {"u": 6}]}


RECORDED = {
    "result": {
        "optimal": {"net_electrical_energy_J": 11453.6, "lengths": {"lift": {"L": 1.25}}},
        "solver": {"iterations": 33, "max_violation_scaled": 3e-10, "total_wall_time_s": 7.4},
        "recheck": {"id_path": "analytic"},
        "cross": [[1.0, None]],
    }
}


def _moved(path: str, value: Any) -> dict[str, Any]:
    fresh = copy.deepcopy(RECORDED)
    node: Any = fresh
    *head, last = path.split(".")
    for step in head:
        node = node[int(step)] if isinstance(node, list) else node[step]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return fresh


@pytest.mark.parametrize(
    ("path", "value"),
    [
        ("result.optimal.net_electrical_energy_J", 11453.6 * (1 + 1.9e-3)),  # within 0.2 %
        ("result.solver.iterations", 36),  # within 10 %
        ("result.solver.max_violation_scaled", 8e-7),  # round-off, both below 1e-6
        ("result.solver.total_wall_time_s", 30.0),  # wall times are not compared
    ],
)
def test_fresh_data_within_the_tolerances_are_current(path: str, value: Any) -> None:
    """Moves a re-run on another CPU makes (and wall times) leave the data current."""
    assert differences(_moved(path, value), RECORDED) == []


@pytest.mark.parametrize(
    ("path", "value"),
    [
        ("result.optimal.net_electrical_energy_J", 11453.6 * (1 + 2.1e-3)),
        ("result.solver.iterations", 37),
        ("result.solver.max_violation_scaled", 2e-6),
        ("result.recheck.id_path", "mujoco"),
        ("result.cross.0.1", 1.0),
        ("result.optimal.lengths", {"lift": {"L": 1.25}, "tilt": {"L": 1.2}}),
    ],
)
def test_fresh_data_beyond_the_tolerances_are_stale(path: str, value: Any) -> None:
    """A number 0.21 % away, four iterations more, a real violation, another string or shape is stale."""
    assert len(differences(_moved(path, value), RECORDED)) == 1


@pytest.mark.parametrize("study", LONG_STUDIES)
def test_long_studies_data_agree_with_their_recorded_optima(study: str) -> None:
    """The long studies' data (not re-run in CI) match tests/data/shipped_optima.json within the data tolerance.

    The record's summary (Xi, iterations, energies) is taken from the committed data by the record's
    own script, and compared with the recorded optimum as :func:`differences` compares fresh data.
    """
    if study not in DATA:
        pytest.skip(f"no recorded run of {study} in docs/results/data (scripts/results_pages.sh records it)")
    checker = load_script("shipped_optima", ROOT / "scripts" / "shipped_optima.py")
    got = checker.summary(DATA[study]["result"])
    want = checker.expected(study)
    assert differences(got, {k: want[k] for k in got}) == []


def test_the_excavator_studies_name_the_period_their_battery_energy_covers() -> None:
    """Each study with a duty (a rest between cycles) reports its battery energy per duty period, not per cycle.

    The recorded 27.650 kJ of the digging study is its 31.8 s cycle and the 6.36 s rest held by the brakes.
    """
    from hiab_sim.docs_site.results_machine_blocks import excavator_studies

    rows = [line for line in excavator_studies(RunData(DATA)).splitlines() if line.startswith("| `optimize/")]
    assert rows and "per cycle" not in excavator_studies(RunData(DATA))
    for row in rows:
        study = row.split("`optimize/")[1].split(".yaml")[0]
        duty = RunData(DATA).result(study)("energy.duty")
        assert f" %) per {'duty period' if duty else 'cycle'} |" in row, study
