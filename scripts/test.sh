#!/usr/bin/env bash
# The test suite (what CI runs): set up, lint (ruff check, ruff format --check, mypy), check that the
# validation table of docs/validation.md matches a fresh `hiab-sim validate`, build the documentation
# site (mkdocs build --strict: a broken link or reference fails), then pytest on 2 workers (the slow
# studies are behind -m slow; arguments go to pytest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export MUJOCO_GL="${MUJOCO_GL:-osmesa}"
export NO_MKDOCS_2_WARNING=1   # mkdocs-material prints a banner about its successor otherwise
.venv/bin/python -m ruff check .
.venv/bin/python -m ruff format --check .
.venv/bin/python -m mypy
validation="$(mktemp -d)"
trap 'rm -rf "$validation"' EXIT
.venv/bin/python -m hiab_sim validate --out "$validation" >"$validation/log" 2>&1 || { cat "$validation/log"; exit 1; }
.venv/bin/python validate/update_readme.py --check --table "$validation/table.md" --page docs/validation.md
.venv/bin/python -m mkdocs build --strict --quiet --site-dir site   # site/ (git-ignored): the browser test opens a page of it
.venv/bin/python -m pytest -n 2 "$@"
