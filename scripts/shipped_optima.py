"""Record or check the optima of the shipped studies (optimize/*.yaml) against tests/data/shipped_optima.json.

A refactoring of the study code must leave every shipped optimum where it was: the optimal link
lengths Xi within 1e-8 m, the energies within 1e-9 relative and the same number of SLSQP iterations.

    python scripts/shipped_optima.py check DIR...           # the recorded optima, deliberate changes included
    python scripts/shipped_optima.py check-baseline DIR...  # main's optima before the change
    python scripts/shipped_optima.py record REASON DIR...   # record the folders' optima under ``changed``

Each DIR is a result folder written by ``hiab-sim optimize optimize/<study>.yaml --out DIR``; the
study is the folder's ``name`` field in result.json. The file holds main's optima (recorded on
8440d36 by running every shipped study there) and, under ``changed``, each deliberate change since
with its reason.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

EXPECTED = Path(__file__).resolve().parents[1] / "tests" / "data" / "shipped_optima.json"
#: Largest difference of an optimal link length [m].
XI_TOLERANCE = 1e-8
#: Largest relative difference of an energy.
ENERGY_TOLERANCE = 1e-9


def _xi(lengths: dict[str, Any]) -> list[float]:
    """Xi [m] of a result's design: a machine file's values in order, or the crane's (lift, tilt) x (L, Lc0, Lc)."""
    if "values" in lengths:
        return [float(v) for v in lengths["values"]]
    return [lengths[chain][key] for chain in ("lift", "tilt") for key in ("L", "Lc0", "Lc")]


def summary(result: dict[str, Any]) -> dict[str, Any]:
    """The compared numbers of one result.json: Xi [m], energies [J], costf2 [W^2 s], iterations."""
    energy = result.get("energy") or {}
    out: dict[str, Any] = {
        "xi_m": _xi(result["optimal"]["lengths"]),
        "iterations": result["solver"]["iterations"],
        "energies": {
            "initial_net_electrical_energy_J": result["initial"]["net_electrical_energy_J"],
            "optimal_net_electrical_energy_J": result["optimal"]["net_electrical_energy_J"],
            "optimal_drawn_energy_summed_drives_J": result["optimal"]["drawn_energy_summed_drives_J"],
        },
    }
    if energy:
        out["energies"]["initial_battery_energy_J"] = energy["initial"]["battery_energy_J"]
        out["energies"]["optimal_battery_energy_J"] = energy["optimal"]["battery_energy_J"]
        out["energies"]["optimal_costf2_W2s"] = energy["optimal"]["costf2_W2s"]
    return out


def differences(got: dict[str, Any], expected: dict[str, Any]) -> list[str]:
    """Human-readable differences beyond the tolerances (empty when the optimum is the same)."""
    out = []
    dxi = max(abs(a - b) for a, b in zip(got["xi_m"], expected["xi_m"], strict=True))
    if dxi > XI_TOLERANCE:
        out.append(f"Xi differs by {dxi:.3e} m")
    if got["iterations"] != expected["iterations"]:
        out.append(f"iterations {got['iterations']} != {expected['iterations']}")
    for key, value in expected["energies"].items():
        rel = abs(got["energies"][key] - value) / max(abs(value), 1e-300)
        if rel > ENERGY_TOLERANCE:
            out.append(f"{key} differs by {rel:.3e} relative ({got['energies'][key]!r} vs {value!r})")
    return out


def expected(name: str, baseline: bool = False) -> dict[str, Any]:
    """The recorded optimum of a study: its deliberate change (``changed``, with its reason) or main's."""
    data = json.loads(EXPECTED.read_text())
    if not baseline and name in data["changed"]:
        return dict(data["changed"][name])
    return dict(data["main_8440d36"][name])


def record(reason: str, folders: list[Path]) -> None:
    """Write each folder's optimum under ``changed`` with ``reason`` (a deliberate change: say why it moved)."""
    if not reason.strip() or os.path.exists(reason):  # (os.path: a long reason is no path, not an OSError)
        raise SystemExit("record needs the reason of the change first, then the result folders")
    data = json.loads(EXPECTED.read_text())
    for folder in folders:
        result = json.loads((folder / "result.json").read_text())
        if result["solver"].get("success") is False:
            raise SystemExit(f"{folder}: the solver did not converge; an optimum that was not reached is not recorded")
        data["changed"][result["name"]] = {**summary(result), "reason": reason}
        print(f"{result['name']}: recorded ({summary(result)['iterations']} iterations)")
    EXPECTED.write_text(json.dumps(data, indent=1) + "\n")


def main(argv: list[str]) -> int:
    """Check or record result folders (module docstring); ``check-baseline`` compares with main's optima only."""
    if argv and argv[0] == "record":
        record(argv[1], [Path(a) for a in argv[2:]])
        return 0
    mode, folders = argv[0], [Path(a) for a in argv[1:]]
    results = {}
    for folder in folders:
        result = json.loads((folder / "result.json").read_text())
        results[result["name"]] = summary(result)
    if mode not in ("check", "check-baseline"):
        raise SystemExit(f"mode must be check or check-baseline, not {mode!r}")
    failed = 0
    for name, got in results.items():
        diffs = differences(got, expected(name, baseline=mode == "check-baseline"))
        print(f"{name}: {'same optimum' if not diffs else '; '.join(diffs)}")
        failed += bool(diffs)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
