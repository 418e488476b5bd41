"""Every shipped study (optimize/*.yaml) reaches its recorded optimum: Xi within 1e-8 m, energies 1e-9, same iterations.

The optima are tests/data/shipped_optima.json: main's before the one study path, and under
``changed`` the deliberate changes and added studies since with their reason (among them every
study on the real drive: the XS 031's default EMLA file and the excavator's with their losses on;
seed_faithful keeps the paper's lossless model). Record a deliberate change with
``python scripts/shipped_optima.py record REASON DIR...``.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType
from unittest.mock import ANY

import pytest
import yaml
from script_helper import load_script

from hiab_sim.study.run import run_study

ROOT = Path(__file__).resolve().parents[1]
_RECORD = json.loads((ROOT / "tests" / "data" / "shipped_optima.json").read_text())
#: main's studies and the ones added since (recorded under ``changed`` with their reason)
STUDIES = sorted({*_RECORD["main_8440d36"], *_RECORD["changed"]})
#: Studies whose solve takes over 30 s on 2 cores (the duty mixes): -m slow, outside CI's budget.
SLOW_STUDIES = {"xs031_duty_mix", "exact_duty_mix"}


def _checker() -> ModuleType:
    return load_script("shipped_optima", ROOT / "scripts" / "shipped_optima.py")


def test_every_shipped_study_has_a_recorded_optimum() -> None:
    """The record covers every study file in optimize/ (the crane and EMLA files are not studies)."""
    studies = {p.stem for p in (ROOT / "optimize").glob("*.yaml") if "\nname:" in "\n" + p.read_text()}
    crane_or_emla = {p.stem for p in (ROOT / "optimize").glob("*.yaml") if "chains:" in p.read_text()}
    assert set(STUDIES) == studies - crane_or_emla


def test_payload_studys_emla_file_is_the_default_but_for_the_lifts_brake() -> None:
    """optimize/emla_xs031_lift_brake70.yaml: the default EMLA file plus the lift's 70 N m brake, nothing else."""
    variant = yaml.safe_load((ROOT / "optimize" / "emla_xs031_lift_brake70.yaml").read_text())
    default = yaml.safe_load((ROOT / "hiab_sim" / "presets" / "emla_xs031.yaml").read_text())
    lift = variant["actuators"]["lift"]
    brake = lift.pop("holding_brake")
    assert brake["holding_torque"]["value"] == 70.0
    assert lift.pop("drive_losses") == {"brake_coil_power": brake["coil_power"] | {"source": ANY}}
    assert brake["coil_power"]["value"] == pytest.approx(24.0 * 1.4, rel=1e-12)
    assert variant == default


@pytest.mark.e2e
@pytest.mark.parametrize(
    "name", [pytest.param(name, marks=pytest.mark.slow) if name in SLOW_STUDIES else name for name in STUDIES]
)
def test_shipped_study_reaches_its_recorded_optimum(name: str, tmp_path: Path) -> None:
    """Optimise the shipped study as ``hiab-sim optimize`` does and compare with the record."""
    checker = _checker()
    out = run_study(ROOT / "optimize" / f"{name}.yaml", tmp_path / name, progress=None, figures=False)
    got = checker.summary(out.result.to_json())
    assert checker.differences(got, checker.expected(name)) == []
