"""Run a sweep's points on an executor; rewrite the table atomically as each point finishes; resume.

Output folder: ``sweep.parquet`` (the table), ``points/<key>/result.json`` (each finished run's
full result) and the summary figures. With ``resume`` the points already in the table (finished,
``ok`` or ``failed``) are skipped; a table of another sweep (another content digest) is refused.
Without ``resume`` an existing table is replaced.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import InvalidInputError
from hiab_sim.sweep.point import PointOutcome, PointTask, result_columns, run_point
from hiab_sim.sweep.spec import Sweep
from hiab_sim.sweep.table import TABLE_NAME, read_table, write_table


@dataclass(frozen=True)
class SweepOutcome:
    """What a call ran: the table path, keys run now, keys skipped (already in the table), keys failed."""

    table: Path
    ran: tuple[str, ...]
    skipped: tuple[str, ...]
    failed: tuple[str, ...]


def sweep_meta(sweep: Sweep) -> dict[str, Any]:
    """The table's metadata: sweep name, file, digest and its number of points."""
    return {"name": sweep.name, "file": str(sweep.file), "digest": sweep.digest, "points": len(sweep.points)}


def _finished(sweep: Sweep, table: Path) -> dict[str, dict[str, Any]]:
    frame, meta = read_table(table)
    if meta.get("digest") != sweep.digest:
        raise InvalidInputError(
            f"--resume ({table})",
            meta.get("file", "unknown"),
            f"the table belongs to another sweep (digest {str(meta.get('digest'))[:12]}, this sweep "
            f"{sweep.digest[:12]}); run without --resume to start afresh",
        )
    return {str(r["key"]): r for r in frame.to_dict("records")}


def run_sweep(
    sweep: Sweep,
    out: Path,
    executor: Executor,
    resume: bool = False,
    progress: bool = True,
    on_row: Callable[[dict[str, Any]], None] | None = None,
) -> SweepOutcome:
    """Run every pending point on ``executor``; the table holds every finished point at all times.

    ``on_row`` is called with each new row after the table is written (a hook for progress or
    for stopping the sweep: an exception there cancels the pending points and propagates).
    """
    out.mkdir(parents=True, exist_ok=True)
    table = out / TABLE_NAME
    done = _finished(sweep, table) if resume and table.is_file() else {}
    order = {p.key: k for k, p in enumerate(sweep.points)}
    rows: dict[str, dict[str, Any]] = {k: r for k, r in done.items() if k in order}
    pending = [p for p in sweep.points if p.key not in rows]
    columns = [*sweep.columns, *result_columns(sweep.design_names)]
    meta = sweep_meta(sweep)
    write_table(table, _ordered(rows, order), columns, meta)
    bar = _bar(len(sweep.points), len(rows), progress)
    ran: list[str] = []
    failed: list[str] = []
    futures: list[Future[PointOutcome]] = [
        executor.submit(
            run_point, PointTask(p.key, p.values, p.study, p.emla, str(sweep.study_file), sweep.design_names)
        )
        for p in pending
    ]
    try:
        for future in as_completed(futures):
            outcome = future.result()
            rows[outcome.key] = {"key": outcome.key, **outcome.row}
            if outcome.result_json is not None:
                write_atomic(out / "points" / outcome.key / "result.json", outcome.result_json)
            write_table(table, _ordered(rows, order), columns, meta)
            ran.append(outcome.key)
            if outcome.row["status"] != "ok":
                failed.append(outcome.key)
            if bar is not None:
                bar.update(1)
                bar.set_postfix(failed=len(failed))
            if on_row is not None:
                on_row(rows[outcome.key])
    finally:
        for future in futures:
            future.cancel()
        if bar is not None:
            bar.close()
    return SweepOutcome(table, tuple(ran), tuple(done), tuple(failed))


def _ordered(rows: dict[str, dict[str, Any]], order: dict[str, int]) -> list[dict[str, Any]]:
    return [rows[k] for k in sorted(rows, key=order.__getitem__)]


def _bar(total: int, initial: int, enabled: bool) -> Any:
    from hiab_sim.terminal import progress_wanted

    if not enabled or not progress_wanted(sys.stderr):  # redirected to a file, a bar would dump every update
        return None
    from tqdm import tqdm

    # leave=False: the bar is wiped when done, so the sweep's answer opens what stays on the terminal
    return tqdm(total=total, initial=initial, desc="sweep points", unit="point", file=sys.stderr, leave=False)
