"""How far an XS 031 optimum is reproducible: one ulp of gravity, and the machine file instead of the crane file.

Each shipped XS 031 study (``crane: xs031``) is optimised three times, one start each:

* ``crane``: as shipped (the crane file's closed-form model);
* ``ulp``: the same, with the crane file's gravity one ulp up (9.8066 -> the next float, 1.8e-16
  relative): a change far below any physical meaning, the study's own reproducibility;
* ``machine``: the same study through ``xs031_machine.yaml`` (the generic tree, tracked
  kinematics and Newton-Euler; the machine file declares the same bounds, ``tracked: [xt2]``).

and the table gives, against ``crane``, the largest change of an optimal length [m] and of an
energy (relative: net electrical, battery, costf2), as ``scripts/shipped_optima.py`` compares them.
A study with a crane-form ``mounting`` section is not compared with the machine file: the machine
form's mounting rows are other rows (its lift-boom sweep runs through every pin on the boom,
``tests/test_machine_mounting.py``), so the problem is not the same.

    python scripts/optimum_reproducibility.py OUT [STUDY...] [--record]   # default: every crane-file study

Result folders go to ``OUT/<study>/<variant>``; a folder with a ``result.json`` is reused (resume).
The numbers go to ``OUT/optimum_reproducibility.json``, with ``--record`` also to :data:`RECORD`.
"""

from __future__ import annotations

import json
import math
import re
import shutil
import sys
from pathlib import Path
from typing import Any

import yaml

import hiab_sim.api as hs

sys.path.insert(0, str(Path(__file__).resolve().parent))  # its sibling, also when loaded by a test
from shipped_optima import summary

REPO = Path(__file__).resolve().parents[1]
STUDIES = REPO / "optimize"
CRANE_FILE = REPO / "hiab_sim" / "presets" / "hiab_xs031.yaml"
VARIANTS = ("crane", "ulp", "machine")
#: The recorded numbers of docs/machine.md's table (``--record``), read back by tests/test_optimum_reproducibility.py.
RECORD = REPO / "tests" / "data" / "xs031_optimum_reproducibility.json"


def _one_ulp_up(crane_text: str) -> str:
    """The crane file with its gravity one ulp up (the line ``gravity: 9.8066``)."""
    g = math.nextafter(9.8066, math.inf)
    changed = re.sub(r"^gravity: 9\.8066\b", f"gravity: {g!r}", crane_text, count=1, flags=re.M)
    if changed == crane_text:
        raise SystemExit(f"{CRANE_FILE}: no line 'gravity: 9.8066' to move by one ulp")
    return changed


def _machine_form(study: dict[str, Any]) -> dict[str, Any]:
    """A crane-file study of the XS 031 as the same study of its machine file (its bounds from the machine file)."""
    bounds = {k: v for k, v in study["bounds"].items() if k not in ("lift", "tilt")}
    if bounds.get("working_range", "crane") == "crane":
        bounds["working_range"] = "machine"
    rest = {k: v for k, v in study.items() if k not in ("crane", "bounds")}
    return rest | {"machine": "xs031", "tracked": ["xt2"], "bounds": bounds}


def _write_variant(study_path: Path, variant: str, folder: Path) -> Path:
    """The study file of one variant in ``folder`` (with the files it names beside it)."""
    folder.mkdir(parents=True, exist_ok=True)
    for file in [*STUDIES.glob("*.yaml"), *STUDIES.glob("*.csv")]:
        shutil.copy(file, folder)
    study = yaml.safe_load(study_path.read_text(encoding="utf-8"))
    if variant == "ulp":
        (folder / "crane_ulp.yaml").write_text(_one_ulp_up(CRANE_FILE.read_text(encoding="utf-8")), encoding="utf-8")
        study["crane"] = "crane_ulp.yaml"
    elif variant == "machine":
        study = _machine_form(study)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(study, sort_keys=False), encoding="utf-8")
    return path


def _optimum(study_path: Path, variant: str, out: Path) -> dict[str, Any]:
    """The compared numbers of one variant's optimum, optimised unless its folder has them."""
    folder = out / variant
    if not (folder / "result" / "result.json").is_file():
        print(f"  {study_path.stem} / {variant} ...", file=sys.stderr, flush=True)
        hs.optimize(_write_variant(study_path, variant, folder), folder / "result", figures=False, progress=None)
    return summary(json.loads((folder / "result" / "result.json").read_text(encoding="utf-8")))


def measure(out: Path, names: list[str]) -> dict[str, dict[str, Any]]:
    """Per study, the compared numbers of each variant it has (a mounting study has no machine variant)."""
    data: dict[str, dict[str, Any]] = {}
    for name in names:
        path = STUDIES / f"{name}.yaml"
        mounting = "mounting" in yaml.safe_load(path.read_text(encoding="utf-8"))
        data[name] = {v: _optimum(path, v, out / name) for v in VARIANTS if not (mounting and v == "machine")}
    return data


def change(got: dict[str, Any], base: dict[str, Any]) -> tuple[float, float]:
    """Largest length change [m] and largest relative energy change of ``got`` against ``base``."""
    dxi = max(abs(a - b) for a, b in zip(got["xi_m"], base["xi_m"], strict=True))
    rel = max(abs(got["energies"][k] - v) / abs(v) for k, v in base["energies"].items())
    return dxi, rel


def table(data: dict[str, dict[str, Any]]) -> str:
    """The markdown table of :func:`measure`'s numbers (docs/machine.md holds it)."""
    lines = [
        "| study | 1 ulp of g: max abs dXi [m] | energies (rel.) | machine file: max abs dXi [m] | energies (rel.) "
        "| SLSQP iterations (crane / 1 ulp / machine) |",
        "|---|---|---|---|---|---|",
    ]
    for name, runs in data.items():
        cells = [f"`{name}`", *(f"{v:.1e}" for v in change(runs["ulp"], runs["crane"]))]
        if "machine" in runs:
            cells += [f"{v:.1e}" for v in change(runs["machine"], runs["crane"])]
        else:
            cells += ["not compared: the machine form's mounting rows are other rows", "-"]
        cells.append(" / ".join(str(runs[v]["iterations"]) for v in VARIANTS if v in runs))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    """Optimise each study's variants, write their numbers and print the table (module docstring)."""
    record = "--record" in argv
    argv = [a for a in argv if a != "--record"]
    if not argv:
        raise SystemExit(__doc__)
    out = Path(argv[0])
    names = argv[1:] or sorted(
        p.stem for p in STUDIES.glob("*.yaml") if re.search(r"^crane: xs031\b", p.read_text(), flags=re.M)
    )
    data = measure(out, names)
    text = json.dumps(data, indent=1) + "\n"
    (out / "optimum_reproducibility.json").write_text(text, encoding="utf-8")
    if record:
        RECORD.write_text(text, encoding="utf-8")
    print(table(data))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
