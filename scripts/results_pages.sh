#!/usr/bin/env bash
# Re-run what the results pages show and regenerate them: every target below writes its output folder
# RUNS/<target> (studies: hiab-sim optimize without figures, video or report; the default run is then
# simulated in closed loop with --payload-error 0.2; the energy map, the two shipped sweeps, the
# Pareto front of the default study and the default study re-optimised per EMLA model level,
# hiab_sim/study/analysis/model_effects.py), each folder's declared fields are recorded into
# docs/results/data/<target>.json and every generated block of docs/results/*.md is rendered from the
# data (hiab_sim/docs_site/results_page.py). Commit docs/results/ afterwards.
#
#   scripts/results_pages.sh                                    # every target (~20 min on 2 quiet cores)
#   ONLY="xs031_spiral exact_digging" scripts/results_pages.sh  # only these, the other data kept
#   scripts/results_pages.sh --from-runs DIR                    # no runs: record DIR/<target>/ and render
#
# RUNS (default runs/results-pages): where the folders go; PYTHON (default .venv/bin/python): the
# interpreter; MIX_STARTS (default 3): the duty mix's starts (the page reports what they reached);
# WORKERS (default 2): the sweeps' local workers. A target that fails stops the script; no data are
# rewritten then.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-.venv/bin/python}"
RUNS="${RUNS:-runs/results-pages}"
TARGETS=(xs031_spiral xs031_spiral_energy xs031_spiral_payload xs031_spiral_mounting seed_scale_spiral
         xs031_codesign xs031_duty_mix exact_digging exact_grading exact_duty_mix
         xs031_spiral_energy_map xs031_mounting_space xs031_payload_gear xs031_spiral_pareto_peak_force
         xs031_spiral_model_effects)
if [ -n "${ONLY:-}" ]; then read -r -a TARGETS <<<"$ONLY"; fi
export MUJOCO_GL="${MUJOCO_GL:-osmesa}"
HS=("$PY" -m hiab_sim)

run_target() {  # run_target NAME OUT: write NAME's output folder OUT
  local name=$1 out=$2
  case "$name" in
    xs031_spiral_energy_map) "${HS[@]}" energy-map optimize/xs031_spiral.yaml --out "$out" ;;
    xs031_spiral_pareto_peak_force) "${HS[@]}" pareto optimize/xs031_spiral.yaml --against peak_force --out "$out" ;;
    xs031_spiral_model_effects) "$PY" -m hiab_sim.study.analysis.model_effects optimize/xs031_spiral.yaml --out "$out" ;;
    xs031_mounting_space | xs031_payload_gear)
      rm -rf "$out"
      "${HS[@]}" sweep "optimize/sweeps/$name.yaml" --workers "${WORKERS:-2}" --out "$out" --quiet ;;
    *)
      local starts=1
      [ "$name" = xs031_duty_mix ] && starts="${MIX_STARTS:-3}"
      "${HS[@]}" optimize "optimize/$name.yaml" --out "$out" --force --starts "$starts" --no-video --no-figures --no-report
      if [ "$name" = xs031_spiral ]; then
        "${HS[@]}" simulate "$out" --payload-error 0.2 --no-video --no-figures --quiet
      fi ;;
  esac
}

if [ "${1:-}" = "--from-runs" ]; then
  RUNS="${2:?--from-runs needs a folder of run folders}"
else
  mkdir -p "$RUNS"
  for name in "${TARGETS[@]}"; do
    echo "running $name -> $RUNS/$name (log: $RUNS/$name.log)"
    run_target "$name" "$RUNS/$name" >"$RUNS/$name.log" 2>&1 || { tail -n 5 "$RUNS/$name.log"; exit 1; }
  done
fi
folders=()
for name in "${TARGETS[@]}"; do
  found=""
  for file in result.json energy_map.json pareto.json sweep.parquet model_effects.json; do [ -f "$RUNS/$name/$file" ] && found=1; done
  if [ -n "$found" ]; then folders+=("$RUNS/$name"); else echo "no finished output of $name in $RUNS: its data are kept"; fi
done
if [ "${#folders[@]}" -gt 0 ]; then "$PY" -m hiab_sim.docs_site.results_page record "${folders[@]}"; fi
"$PY" -m hiab_sim.docs_site.results_page render
"$PY" -m hiab_sim.docs_site.results_page render --check
