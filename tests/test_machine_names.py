"""No module of the package spells a machine's names: no string literal equals a shipped link, joint or actuator name.

The names are read from the shipped machine files (hiab_sim/presets: the XS 031 and the eXact
excavator): links, joints, chains (actuators), their EMLAs, bodies and decision variables. Every
module under hiab_sim/ is parsed; a string constant equal to one of them is a finding unless the
module is one of the exempt modules below, each with its reason, or the (module, literal) pair is
a word of another meaning there. An exemption that no longer finds anything fails the test too,
so the list only shrinks.
"""

from __future__ import annotations

import ast
from pathlib import Path

import hiab_sim
from hiab_sim.machine.chains import PIVOT_ROLES
from hiab_sim.machine.loader import PRESETS, load_machine

PACKAGE = Path(hiab_sim.__file__).resolve().parent
#: Words of the file format itself (pivot roles, chain body names); a machine may reuse one as a name.
FORMAT_WORDS = {role for roles in PIVOT_ROLES.values() for role in roles} | {"cylinder", "rod", "pin", "hinge"}
#: The seed paper's symbols of a triangle chain's xi = [L, Lc0, Lc] and of the retracted length x0 = Lc0 + Lc:
#: notation the paper defines for any chain (a machine file may name its variables after it), not a machine's names.
NOTATION = {"L", "Lc0", "Lc", "x0"}

#: Modules that keep the XS 031's names. The crane file format (hiab_sim/presets/hiab_xs031.yaml) fixes its
#: chains (lift, tilt), its telescope section, joints (theta1, theta2, xt2), links and bodies; its schema spells
#: them once, and the crane file's loader, dataclasses, kinematics, dynamics and MJCF builder import them from
#: there. A machine file (hiab_sim/machine) describes the same crane without any of them.
CRANE_MODEL = {
    "crane/names.py": "the crane file format's schema, the one module that spells its fixed section and body names",
}
#: (module, literal) pairs where the word has another meaning than the machine's name.
OTHER_MEANING = {
    ("study/figures/optimisation.py", "alpha"): "matplotlib's opacity keyword",
    ("model/mjcf.py", "boom"): "the MJCF template's visual default class of structure capsules (crane_template.xml)",
    ("study/references/csv_file.py", "telescope"): "a study key: a TCP file's held third coordinate",
    ("study/references/kinds.py", "telescope"): "a study key of the spiral and pick-and-place kinds",
    ("docs_site/field_specs/references.py", "telescope"): "documents that study key",
}


def shipped_names() -> set[str]:
    """Every name the shipped machine files give, less the format's words and the paper's notation."""
    names: set[str] = set()
    for preset in PRESETS:
        machine = load_machine(preset)
        names |= {link.name for link in machine.links} | set(machine.joint_names) | set(machine.actuator_names)
        names |= {c.actuator.emla for c in machine.chains}
        names |= {v.name for v in machine.decision_variables} | {b.name for link in machine.links for b in link.parts}
    return names - FORMAT_WORDS - NOTATION


def name_literals(names: set[str]) -> dict[str, list[tuple[int, str]]]:
    """Per module (relative to the package): the line and value of each string constant that is a name."""
    found: dict[str, list[tuple[int, str]]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        module = path.relative_to(PACKAGE).as_posix()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names:
                found.setdefault(module, []).append((node.lineno, node.value))
    return found


def test_the_names_come_from_both_shipped_machines() -> None:
    """The set holds the XS 031's and the excavator's link, joint and actuator names, not the format's words."""
    names = shipped_names()
    assert {"lift", "tilt", "telescope", "theta1", "theta2", "xt2", "telescope_rod", "lift_boom"} <= names
    assert {"boom", "arm", "bucket", "alpha", "beta", "gamma", "chassis", "Gx"} <= names
    assert not names & (FORMAT_WORDS | NOTATION)


def test_no_module_outside_the_crane_model_spells_a_machines_names() -> None:
    """Outside :data:`CRANE_MODEL` no string constant is a shipped name, but for :data:`OTHER_MEANING`'s words."""
    found = [
        f"{module}:{line}: {value!r}"
        for module, hits in name_literals(shipped_names()).items()
        if module not in CRANE_MODEL
        for line, value in hits
        if (module, value) not in OTHER_MEANING
    ]
    assert not found, found


def test_every_exemption_is_still_needed() -> None:
    """Each exempt module still spells a name, each other-meaning pair still occurs: a stale entry is removed."""
    found = name_literals(shipped_names())
    assert sorted(set(CRANE_MODEL) - set(found)) == []
    pairs = {(module, value) for module, hits in found.items() for _, value in hits}
    assert sorted(set(OTHER_MEANING) - pairs) == []
