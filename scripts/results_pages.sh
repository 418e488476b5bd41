#!/usr/bin/env bash
# Re-run the studies behind the results pages and regenerate them: every study of STUDIES is optimised
# into RUNS/<study> (no figures, video or report), the default run is simulated in closed loop
# (--payload-error 0.2), each run's declared fields are recorded into docs/results/data/<study>.json and
# every generated block of docs/results/*.md is rendered from those data
# (hiab_sim/docs_site/results_page.py). Commit docs/results/ afterwards.
#
#   scripts/results_pages.sh                         # every study (~15 min on 2 shared cores)
#   ONLY="xs031_spiral exact_digging" scripts/results_pages.sh   # only these studies, the rest's data kept
#   scripts/results_pages.sh --from-runs DIR          # no optimisation: record DIR/<study>/ folders and render
#
# RUNS (default runs/results-pages) is where the run folders go; PYTHON (default .venv/bin/python) runs them.
# A study that fails stops the script (its data are not rewritten); the duty mix runs with --starts 3
# (the page reports its starts).
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-.venv/bin/python}"
RUNS="${RUNS:-runs/results-pages}"
STUDIES=(xs031_spiral xs031_spiral_energy xs031_spiral_payload xs031_spiral_mounting seed_scale_spiral
         xs031_codesign xs031_duty_mix exact_digging exact_grading)
if [ -n "${ONLY:-}" ]; then read -r -a STUDIES <<<"$ONLY"; fi
export MUJOCO_GL="${MUJOCO_GL:-osmesa}"

if [ "${1:-}" = "--from-runs" ]; then
  RUNS="${2:?--from-runs needs a folder of run folders}"
else
  mkdir -p "$RUNS"
  for study in "${STUDIES[@]}"; do
    starts=1
    [ "$study" = xs031_duty_mix ] && starts=3
    echo "optimising $study -> $RUNS/$study"
    "$PY" -m hiab_sim optimize "optimize/$study.yaml" --out "$RUNS/$study" --force --starts "$starts" \
      --no-video --no-figures --no-report >"$RUNS/$study.log" 2>&1 || { tail -n 5 "$RUNS/$study.log"; exit 1; }
    if [ "$study" = xs031_spiral ]; then
      "$PY" -m hiab_sim simulate "$RUNS/$study" --payload-error 0.2 --no-video --no-figures --quiet >>"$RUNS/$study.log" 2>&1
    fi
  done
fi
folders=()
for study in "${STUDIES[@]}"; do
  if [ -f "$RUNS/$study/result.json" ]; then folders+=("$RUNS/$study"); else echo "no run of $study in $RUNS: its data are kept"; fi
done
[ "${#folders[@]}" -gt 0 ] && "$PY" -m hiab_sim.docs_site.results_page record "${folders[@]}"
"$PY" -m hiab_sim.docs_site.results_page render
"$PY" -m hiab_sim.docs_site.results_page render --check
