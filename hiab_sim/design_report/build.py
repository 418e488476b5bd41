"""Assemble the design report of a result folder and write it (HTML, optionally PDF)."""

from __future__ import annotations

from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import Crane
from hiab_sim.design_report.analysis import (
    closed_loop,
    constraints,
    duty_mix,
    hydraulics,
    sensitivities,
    structure,
    thermal,
)
from hiab_sim.design_report.answer import design, energies, machine_design, question
from hiab_sim.design_report.page import document
from hiab_sim.design_report.provenance import provenance
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.read import read_result, result_crane, result_machine

REPORT_FILE = "report.html"


def report_html(run_dir: str | Path) -> str:
    """The report of ``run_dir`` as one self-contained HTML page (figures embedded, no network reference)."""
    folder = Path(run_dir)
    result = read_result(folder)
    machine: Crane | Machine
    if isinstance(result.optimal.lengths, MachineDesign):
        machine = result_machine(folder, result)
        answer = machine_design(result, machine, folder)
    else:
        machine = result_crane(folder, result.crane)
        answer = design(result, machine, folder)
    body = [
        question(result, machine),
        answer,
        energies(result, folder),
        constraints(result),
        thermal(result),
        sensitivities(result, folder),
        structure(result, folder),
        hydraulics(result, folder),
        closed_loop(folder),
        duty_mix(result, folder),
        provenance(result, folder),
    ]
    return document(f"Design report: {result.name} on the {machine.name}", body)


def write_report(run_dir: str | Path, out: str | Path | None = None, pdf: bool = False) -> list[Path]:
    """Write ``report.html`` (default: in ``run_dir``) and with ``pdf`` the same page as PDF; return the files."""
    html_file = Path(run_dir) / REPORT_FILE if out is None else Path(out)
    write_atomic(html_file, report_html(run_dir))
    written = [html_file]
    if pdf:
        from hiab_sim.design_report.pdf import print_pdf

        written.append(print_pdf(html_file, html_file.with_suffix(".pdf")))
    return written
