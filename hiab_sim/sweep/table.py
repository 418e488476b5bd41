"""The sweep table: one row per point, one Parquet file written atomically, tagged with its sweep.

The file's schema metadata ``hiab_sim_sweep`` holds the sweep's name and content digest, so
``--resume`` refuses a table of another sweep. Rows are kept in the sweep's point order (not
completion order), so the same sweep gives the same table on any executor.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import ConfigError

META_KEY = b"hiab_sim_sweep"
TABLE_NAME = "sweep.parquet"


def write_table(path: Path, rows: list[dict[str, Any]], columns: list[str], meta: dict[str, Any]) -> None:
    """Write ``rows`` (dicts with ``key`` and ``columns``) as Parquet, atomically."""
    frame = pd.DataFrame(rows, columns=["key", *columns])
    table = pa.Table.from_pandas(frame, preserve_index=False)
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), META_KEY: json.dumps(meta).encode()})
    buffer = io.BytesIO()
    pq.write_table(table, buffer)
    write_atomic(path, buffer.getvalue())


def read_table(path: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Read a sweep table and its sweep metadata; a file that is not one raises ConfigError."""
    try:
        table = pq.read_table(path)
    except (OSError, pa.ArrowInvalid) as error:
        raise ConfigError(f"{path}: not a readable sweep table ({error})") from None
    raw = (table.schema.metadata or {}).get(META_KEY)
    if raw is None:
        raise ConfigError(f"{path}: a Parquet file without hiab-sim sweep metadata")
    return table.to_pandas(), json.loads(raw)
