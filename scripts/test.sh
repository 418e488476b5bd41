#!/usr/bin/env bash
# The test suite: set up, then run pytest on 2 workers (the slow studies are behind -m slow).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export MUJOCO_GL="${MUJOCO_GL:-osmesa}"
.venv/bin/python -m pytest -n 2 "$@"
