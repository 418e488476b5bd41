#!/usr/bin/env bash
# Re-make docs/figures/ from the tool: the validation page's figures (MuJoCo vs analytic inverse
# dynamics over the cases of `hiab-sim validate`, and the balance residuals), the default study's
# figures, three frames (start, middle, end) of the playback and closed-loop videos, the EMLA map and
# the energy map, and three frames of the eXact excavator's digging video (excavator_<start|middle|end>.png).
# With SLOW=1 also the sweeps and the Pareto front (tens of optimisations). Run after scripts/setup.sh.
# ONLY=validation makes the validation figures only (seconds), ONLY=excavator the excavator's frames only
# (its optimisation: minutes), ONLY=crane everything but the excavator's frames; FIGURES_DIR (default docs/figures), VALIDATION_SAMPLES (default: the case
# file's), PYTHON (default .venv/bin/python) and HIAB_SIM (default .venv/bin/hiab-sim) change where they go,
# how many samples per case and which interpreter and command run them (the test uses the first three).
set -euo pipefail
cd "$(dirname "$0")/.."
HS="${HIAB_SIM:-.venv/bin/hiab-sim}"
RUN="${RUN_DIR:-runs/docs_xs031_spiral}"
EXCAVATOR_RUN="${EXCAVATOR_RUN_DIR:-runs/docs_exact_digging}"
PY="${PYTHON:-.venv/bin/python}"
OUT="${FIGURES_DIR:-docs/figures}"
mkdir -p "$OUT"
# The excavator (a machine file's study): its playback dressed from the machine description, three frames
# evenly spaced over the digging cycle, ends included (the optimal design over the ghost of the initial one).
# REUSE=1 keeps an excavator result folder that already holds a result.json (no new optimisation).
excavator_frames() {
  if [ "${REUSE:-0}" != "1" ] || [ ! -f "$EXCAVATOR_RUN/result.json" ]; then
    $HS optimize optimize/exact_digging.yaml --out "$EXCAVATOR_RUN" --force --no-video --no-figures --no-report \
      --quiet >/dev/null
  fi
  local frames="$EXCAVATOR_RUN/docs_frames"
  rm -rf "$frames" && mkdir -p "$frames"
  $HS render "$EXCAVATOR_RUN" --frames "$frames" --count 3 --size 800x450 >/dev/null
  mv "$frames/frame_000.png" "$OUT/excavator_start.png"
  mv "$frames/frame_001.png" "$OUT/excavator_middle.png"
  mv "$frames/frame_002.png" "$OUT/excavator_end.png"
}
if [ "${ONLY:-}" = "excavator" ]; then
  excavator_frames
  echo "re-made the excavator's frames in $OUT from $EXCAVATOR_RUN"
  exit 0
fi
$PY -m hiab_sim.docs_site.validation_figures --out "$OUT" ${VALIDATION_SAMPLES:+--samples "$VALIDATION_SAMPLES"} >/dev/null
if [ "${ONLY:-}" = "validation" ]; then
  echo "re-made the validation figures in $OUT"
  exit 0
fi
$HS optimize --starts 3 --out "$RUN" --force >/dev/null
for name in objective decision_variables_lift decision_variables_tilt structure_initial_vs_optimal crane_spiral \
            actuators_force_velocity_power efficiency_maps energy_breakdown sensitivity energy_emla_vs_hydraulic; do
  cp "$RUN/$name.png" "$OUT/$name.png"
done
# The playback: a GIF for the README, its still, and three frames at the start, middle and end.
$HS render "$RUN" -o "$OUT/render_playback.gif" --fps 10 --size 480x270 >/dev/null
$HS render "$RUN" --still "$OUT/render_playback.png" --at 2.0 --size 800x450 >/dev/null
duration=$(.venv/bin/python -c "import json,sys; r=json.load(open('$RUN/result.json')); print(r['settings']['collocation_step_s'] * (r['settings']['collocation_points'] - 1))")
for which in start middle end; do
  at=$(.venv/bin/python -c "d=$duration; print({'start': 0.0, 'middle': d / 2, 'end': d}['$which'])")
  $HS render "$RUN" --still "$OUT/playback_$which.png" --at "$at" --size 800x450 >/dev/null
done
# The closed loop (planned end mass and +20 %), its video's three frames.
$HS simulate "$RUN" --payload-error 0.2 --quiet >/dev/null 2>&1
for which in start middle end; do
  at=$(.venv/bin/python -c "d=$duration; print({'start': 0.0, 'middle': d / 2, 'end': d - 0.05}['$which'])")
  ffmpeg -loglevel error -y -ss "$at" -i "$RUN/closed_loop.mp4" -frames:v 1 "$OUT/closed_loop_$which.png"
done
cp "$RUN/closed_loop_energy.png" "$OUT/closed_loop_energy.png"
$HS emla-map -o "$OUT/emla_map_lift.png" >/dev/null
$HS energy-map --result "$RUN" --out "$RUN/energy_map" >/dev/null
cp "$RUN/energy_map/energy_map.png" "$OUT/energy_map_xs031.png"
# A map whose cells are all infeasible, to show how the figure says why.
$HS energy-map --result "$RUN" --vars lift.L,tilt.L --out "$RUN/energy_map_infeasible" >/dev/null
cp "$RUN/energy_map_infeasible/energy_map.png" "$OUT/energy_map_infeasible.png"
if [ "${SLOW:-0}" = "1" ]; then
  $HS pareto --against peak_force --out "$RUN/pareto_peak_force" >/dev/null
  cp "$RUN/pareto_peak_force/pareto.png" "$OUT/pareto_peak_force.png"
  $HS sweep sweeps/xs031_mounting_space --out "$RUN/sweep_mounting_space" >/dev/null
  cp "$RUN/sweep_mounting_space/sweep_summary.png" "$OUT/sweep_mounting_space.png"
  $HS sweep sweeps/xs031_payload_gear --out "$RUN/sweep_payload_gear" >/dev/null
  cp "$RUN/sweep_payload_gear/sweep_summary.png" "$OUT/sweep_payload_gear.png"
  cp "$RUN/sweep_payload_gear/sweep_saving_map.png" "$OUT/sweep_payload_gear_map.png"
fi
if [ "${ONLY:-}" = "crane" ]; then
  echo "re-made $OUT from $RUN (the excavator's frames kept)"
  exit 0
fi
excavator_frames
echo "re-made $OUT from $RUN and $EXCAVATOR_RUN"
