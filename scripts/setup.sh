#!/usr/bin/env bash
# Idempotent set-up on a fresh Debian machine: system libraries (OSMesa for off-screen
# rendering, ffmpeg for videos, Chromium for the report's PDF and the browser tests), a virtual
# environment in .venv and hiab-sim with its extras (docs: the documentation site).
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi
need=""
dpkg -s libosmesa6 >/dev/null 2>&1 || need="$need libosmesa6"
command -v ffmpeg >/dev/null 2>&1 || need="$need ffmpeg"
command -v chromium >/dev/null 2>&1 || need="$need chromium"   # the report's --pdf and the browser tests
python3 -c "import ensurepip, venv" >/dev/null 2>&1 || need="$need python3-venv"   # Debian splits venv out
if [ -n "$need" ]; then
  echo "[setup] apt-get install$need"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $need >/dev/null
fi
# An existing .venv with another MuJoCo line (e.g. 4.x, whose split packages mujoco-core and
# mujoco-studio break `import mujoco` when pip downgrades them in place) is rebuilt from scratch.
if [ -x .venv/bin/python ] && ! .venv/bin/python -c "import mujoco, sys; sys.exit(not mujoco.__version__.startswith('3.17.'))" >/dev/null 2>&1; then
  echo "[setup] .venv has no working MuJoCo 3.17: recreating it"
  rm -rf .venv
fi
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip >/dev/null
.venv/bin/python -m pip install -q -e ".[test,dev,dask,ipopt,docs]"
