"""``hiab-sim mjcf --machine``: write a machine file's generic MJCF for one design (see :mod:`hiab_sim.cli.mjcf`)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine_mjcf import machine_mjcf, parse_design, result_design


def machine_and_design(args: argparse.Namespace, result_choice: str | None) -> tuple[Machine, np.ndarray]:
    """The machine and its design values [m]: from ``--from-result`` or from ``--machine`` and ``--design`` items."""
    if args.from_result is None:
        machine = load_machine(args.machine)
        return machine, parse_design(machine, args.design or [])
    if args.lengths:
        raise InvalidInputError("--lengths", args.lengths, "cannot be combined with --from-result")
    from hiab_sim.results.read import design_lengths, read_result, result_machine

    result = read_result(args.from_result)
    machine = result_machine(args.from_result, result)
    if args.machine is not None and load_machine(args.machine).name != machine.name:
        raise InvalidInputError("--machine", args.machine, f"differs from the result's machine {machine.name}")
    design = design_lengths(result, str(result_choice))
    if not isinstance(design, MachineDesign):
        raise InvalidInputError("--from-result", args.from_result, "is a crane file's result")
    return machine, result_design(machine, design, "--from-result")


def run_machine(args: argparse.Namespace, result_choice: str | None) -> int:
    """Write the machine's MJCF and print one line: the machine, its design and the model's size."""
    import mujoco

    if args.lengths:
        raise InvalidInputError(
            "--lengths",
            args.lengths,
            "must be left out for a machine file (a crane file's lengths): give its design as --design chain.var=value",
        )
    if args.stroke_margin:
        raise InvalidInputError(
            "--stroke-margin",
            args.stroke_margin,
            "must be left out for a machine file (a crane file's option): a machine file keeps its working ranges",
        )
    machine, design = machine_and_design(args, result_choice)
    output = Path(args.output)
    if not output.parent.is_dir():
        raise InvalidInputError("--output", str(output), "its folder must exist")
    # a typed design is checked against the file's bounds; a result's is the solver's (IPOPT may end 1e-8 past one)
    text = machine_mjcf(machine.with_design(design, check_bounds=result_choice is None))
    model = mujoco.MjModel.from_xml_string(text)
    write_atomic(output, text)
    values = ", ".join(f"{k} = {v:.10g}" for k, v in zip(machine.variable_keys, design, strict=True))
    print(
        f"wrote {output}: {machine.name}, {values or 'no decision variables'} [m], "
        f"{model.nbody - 1} bodies, {model.nv} dofs, {model.neq} loop pins"
    )
    return 0
