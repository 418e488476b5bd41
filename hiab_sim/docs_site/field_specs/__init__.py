"""The documented keys of every file format, built from the dataclasses and readers that own them.

Each format is a list of :class:`Key` rows: a *section* (a mapping whose keys are listed after it), a
*value*, *free* (any name or dotted path) or *names* (names another file defines, which the loader
checks against it: a machine's decision variables); a row with a ``form`` belongs to that form of the
file only (a study's ``crane`` or ``machine`` form, :class:`hiab_sim.docs_site.formats.Form`).
Where a reader builds a dataclass from a section
(:func:`hiab_sim.yaml_fields.section` and its kin), the rows come from that dataclass
(:func:`~hiab_sim.docs_site.dataclass_fields.field_rows`: its type, default, the docstring's
description and unit, the range its ``__post_init__`` checks); the keys a reader handles by hand are
written once, next to the reader's name. One module per format (:mod:`.machine`, :mod:`.crane`, :mod:`.emla`,
:mod:`.study` with :mod:`.references`, :mod:`.soil`, :mod:`.sweep`, :mod:`.cases`), the row helpers in :mod:`.rows`;
:data:`KEYS` names them all. ``tests/test_file_formats.py`` holds these rows to the keys the loaders
accept (:mod:`hiab_sim.docs_site.probe`).
"""

from __future__ import annotations

from collections.abc import Callable

from hiab_sim.docs_site.field_specs.cases import cases_keys
from hiab_sim.docs_site.field_specs.crane import crane_keys
from hiab_sim.docs_site.field_specs.emla import emla_keys
from hiab_sim.docs_site.field_specs.machine import machine_keys
from hiab_sim.docs_site.field_specs.rows import Key
from hiab_sim.docs_site.field_specs.soil import soil_keys
from hiab_sim.docs_site.field_specs.study import study_keys
from hiab_sim.docs_site.field_specs.sweep import sweep_keys

__all__ = ["KEYS", "Key"]

#: Format name (:data:`hiab_sim.docs_site.formats.FORMATS`) -> its documented keys.
KEYS: dict[str, Callable[[], list[Key]]] = {
    "machine": machine_keys,
    "crane": crane_keys,
    "emla": emla_keys,
    "study": study_keys,
    "soil": soil_keys,
    "sweep": sweep_keys,
    "cases": cases_keys,
}
