"""Generic machine code spells no machine's names: no string literal equals a shipped link, joint or chain name."""

from __future__ import annotations

import ast
from pathlib import Path

import hiab_sim
from hiab_sim.machine.chains import PIVOT_ROLES
from hiab_sim.machine.loader import PRESETS, load_machine

PACKAGE = Path(hiab_sim.__file__).resolve().parent
#: Every module of the machine package (description, closure, dynamics, MJCF) and the machine CLI.
GENERIC = [*sorted((PACKAGE / "machine").glob("*.py")), PACKAGE / "cli" / "machine.py"]
#: Words of the file format itself (pivot roles, chain body names); a machine may reuse one as a name.
FORMAT_WORDS = {role for roles in PIVOT_ROLES.values() for role in roles} | {"cylinder", "rod", "pin", "hinge"}


def _shipped_names() -> set[str]:
    names: set[str] = set()
    for preset in PRESETS:
        machine = load_machine(preset)
        names |= {link.name for link in machine.links} | set(machine.joint_names) | set(machine.actuator_names)
        names |= {v.name for v in machine.decision_variables} | {b.name for link in machine.links for b in link.parts}
    return names - FORMAT_WORDS


def test_generic_machine_modules_hold_no_machine_names_as_literals() -> None:
    """No string constant in the generic machine modules equals a name a shipped machine file gives.

    Words of the format itself (the pivot role ``base``, also the XS 031's root link) are not names.
    """
    names = _shipped_names()
    assert {"lift", "theta1", "telescope_rod", "boom", "bucket", "gamma"} <= names
    found = []
    for path in GENERIC:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names:
                found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: {node.value!r}")
    assert not found, found
