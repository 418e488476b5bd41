"""The file formats hiab-sim reads: each one's loader (a parsed document in, a checked object out) and valid examples.

:mod:`hiab_sim.docs_site.probe` asks these loaders which keys they accept; the test of the file-format
reference compares that with the keys :mod:`hiab_sim.docs_site.field_specs` documents.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from hiab_sim.resources import Source, shipped, shipped_names
from hiab_sim.yaml_fields import parse_yaml


@dataclass(frozen=True)
class Form:
    """One form of a file format, chosen by the top-level key ``key`` (a study names a ``crane`` or a ``machine``).

    The keys of each form are compared with what the loader accepts on the documents of that form only;
    a key documented for other forms only must make the loader fail on this form's documents.
    """

    name: str
    key: str
    description: str

    def holds(self, document: Any) -> bool:
        """Whether ``document`` is of this form."""
        return isinstance(document, dict) and self.key in document


@dataclass(frozen=True)
class FileFormat:
    """One kind of file: its title, what reads it, valid documents to probe the loader with, and its forms."""

    name: str
    title: str
    reader: str  # the function that reads it, for the page
    load: Callable[[Any], object]
    documents: Callable[[], list[Any]]
    forms: tuple[Form, ...] = ()  # none: one form


def _parsed(source: Source) -> Any:
    return parse_yaml(source.read_text())


def _load_crane(document: Any) -> object:
    from hiab_sim.crane.loader import crane_from_dict

    return crane_from_dict(document)


def _load_machine(document: Any) -> object:
    from hiab_sim.machine.loader import machine_from_dict

    return machine_from_dict(document)


def _machine_documents() -> list[Any]:
    """Both shipped machines, and the excavator with its four-bar chain first.

    The probe's ``<chain>`` is a document's first chain: the reordered copy lets it reach the
    ``linkage`` keys (and their bodies) on a chain that has a four-bar.
    """
    from hiab_sim.machine.loader import PRESETS, read_machine_yaml

    documents = [read_machine_yaml(shipped("machine", name)) for name in sorted(PRESETS, reverse=True)]
    for document in list(documents):
        chains = document["chains"]
        linkages = [name for name, chain in chains.items() if chain.get("kind") == "linkage"]
        if linkages:
            first = linkages[0]
            documents.append({**document, "chains": {first: chains[first], **chains}})
    return documents


def _load_emla(document: Any) -> object:
    from hiab_sim.emla.config import emla_set_from_mapping

    return emla_set_from_mapping(document)


#: Control points of a machine study's CSV fit in the probe's documents (see :func:`_study_documents`).
_PROBE_FIT_POINTS = 80


def _study_documents() -> list[Any]:
    """The shipped studies; a machine file's study with tasks also as one ``reference`` (+ ``payload``).

    The shipped machine study is a duty mix of one task: its single-reference copy lets the probe reach
    the top-level ``reference`` and ``payload`` of the machine form. The probe loads each document dozens
    of times; a CSV reference's fit there takes :data:`_PROBE_FIT_POINTS` control points (its default
    by duration costs seconds per load; the shipped digging cycle passes its fit tolerance with these).
    """
    from hiab_sim.machine.loader import load_machine
    from hiab_sim.machine.mounting import moved_pivots

    names = sorted(shipped_names("study"))
    out = []
    for name in names:
        document = _parsed(shipped("study", name))
        if isinstance(document, dict) and ("reference" in document or "tasks" in document):
            out.append(document)
            if "machine" in document and document.get("tasks"):
                for task in document["tasks"]:
                    if task["reference"].get("kind") == "csv":
                        task["reference"].setdefault("control_points", _PROBE_FIT_POINTS)
                task = document["tasks"][0]
                single = {k: v for k, v in document.items() if k != "tasks"}
                single["reference"] = task["reference"]
                single.update({k: task[k] for k in ("payload",) if k in task})
                single["spline"] = {**single.get("spline", {}), **{"control_points": task["control_points"]}}
                out.append(single)
                # and with a transmission catalogue for its first actuator and a polygon on its first moved
                # pivot (the probe reaches the machine form's entries of both)
                machine = load_machine(str(document["machine"]))
                first = machine.actuator_names[0]
                out.append({**single, "transmission": {first: [{"gear_ratio": 5.0, "screw_lead": 0.01}]}})
                chain, role = moved_pivots(machine)[0]
                out.append({**single, "mounting": {chain: {role: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]}}})
    return out


def _load_study(document: Any) -> object:
    from hiab_sim.study.spec.study_file import study_from_dict

    return study_from_dict(document, shipped("study", "xs031_spiral"))


def _via_file(document: Any, reader: Callable[[Path], object]) -> object:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "probe.yaml"
        path.write_text(yaml.safe_dump(document))
        return reader(path)


def _load_soil(document: Any) -> object:
    from hiab_sim.machine.dynamics.soil_file import soil_from_mapping

    return soil_from_mapping(document)


def _soil_documents() -> list[Any]:
    from hiab_sim.machine.dynamics.soil_file import SOILS

    return [_parsed(shipped("soil", name)) for name in sorted(SOILS)]


def _load_sweep(document: Any) -> object:
    from hiab_sim.sweep.spec import load_sweep

    return _via_file(document, load_sweep)


def _sweep_documents() -> list[Any]:
    sample = {"study": "xs031_spiral", "sample": {"points": 2, "seed": 1, "ranges": {"payload": [0.0, 100.0]}}}
    return [sample, {"study": "xs031_spiral", "name": "grid", "set": {"solver.maxiter": 5}, "grid": {"payload": [0.0]}}]


def _load_cases(document: Any) -> object:
    from hiab_sim.validation import load_cases

    return _via_file(document, load_cases)


def _cases_documents() -> list[Any]:
    document = _parsed(shipped("cases", "cases"))
    one = {"cases": [{**document["cases"][0], "payload": "none"}]}
    return [document, one]


FORMATS: dict[str, FileFormat] = {
    f.name: f
    for f in (
        FileFormat(
            "machine",
            "Machine file",
            "hiab_sim.machine.loader.load_machine",
            _load_machine,
            _machine_documents,
        ),
        FileFormat(
            "crane",
            "Crane file",
            "hiab_sim.crane.loader.load_crane",
            _load_crane,
            lambda: [_parsed(shipped("crane", "xs031"))],
        ),
        FileFormat(
            "emla",
            "EMLA file",
            "hiab_sim.emla.config.load_emla_set",
            _load_emla,
            lambda: [_parsed(shipped("emla", name)) for name in ("default", "exact")],  # the crane's names, a machine's
        ),
        FileFormat(
            "study",
            "Study file",
            "hiab_sim.study.spec.study_file.load_study",
            _load_study,
            _study_documents,
            (
                Form("crane", "crane", "a crane file's study (`crane:`)"),
                Form("machine", "machine", "a machine file's study (`machine:`, `study_file.machine_study_from_dict`)"),
            ),
        ),
        FileFormat(
            "soil",
            "Soil file",
            "hiab_sim.machine.dynamics.soil_file.load_soil",
            _load_soil,
            _soil_documents,
        ),
        FileFormat("sweep", "Sweep file", "hiab_sim.sweep.spec.load_sweep", _load_sweep, _sweep_documents),
        FileFormat(
            "cases",
            "Validation cases file",
            "hiab_sim.validation.load_cases",
            _load_cases,
            _cases_documents,
        ),
    )
}
