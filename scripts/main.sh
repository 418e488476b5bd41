#!/usr/bin/env bash
# The main job: set up, optimise the default crane (HIAB XS 031) on the default study, then validate
# both designs in closed loop (simulated EMLA drives + tracking controller), render the result and write
# the design report (RUN_DIR/report.html).
# Arguments go to `hiab-sim optimize`; RUN_DIR (default runs/xs031_spiral) is the result folder.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
RUN_DIR="${RUN_DIR:-runs/xs031_spiral}"
.venv/bin/hiab-sim crane
.venv/bin/hiab-sim optimize --starts 3 --out "$RUN_DIR" "$@"
.venv/bin/hiab-sim simulate "$RUN_DIR" --payload-error 0.2
.venv/bin/hiab-sim report "$RUN_DIR"   # the design report again, now with the closed-loop validation
