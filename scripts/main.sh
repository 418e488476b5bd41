#!/usr/bin/env bash
# The main job: set up, optimise the default crane (HIAB XS 031) on the default study, then validate
# both designs in closed loop (simulated EMLA drives + tracking controller), render the result and write
# the design report (RUN_DIR/report.html).
# Arguments go to `hiab-sim optimize`; RUN_DIR (default runs/xs031_spiral) is the result folder.
# The set-up's own output (pip, apt) goes to .venv-setup.log; it is shown only when the set-up fails.
set -euo pipefail
cd "$(dirname "$0")/.."
SETUP_LOG=".venv-setup.log"
if ! bash scripts/setup.sh >"$SETUP_LOG" 2>&1; then
  tail -n 40 "$SETUP_LOG" >&2
  echo "set-up failed (full log: $SETUP_LOG)" >&2
  exit 1
fi
echo "set-up done (log: $SETUP_LOG)"
RUN_DIR="${RUN_DIR:-runs/xs031_spiral}"
.venv/bin/hiab-sim optimize --starts 3 --out "$RUN_DIR" "$@"
.venv/bin/hiab-sim simulate "$RUN_DIR" --payload-error 0.2
.venv/bin/hiab-sim report "$RUN_DIR"   # the design report again, now with the closed-loop validation
