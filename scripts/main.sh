#!/usr/bin/env bash
# The main job: set up, then optimise the default crane (HIAB XS 031) on the default study.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
.venv/bin/hiab-sim crane
.venv/bin/hiab-sim optimize --starts 3 "$@"
