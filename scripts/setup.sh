#!/usr/bin/env bash
# One-time set-up on Debian/Ubuntu: the system libraries open3d needs and a virtual
# environment with hiper and its dev tools. Safe to run again: it skips what is done.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${VENV:-.venv}"
PYTHON="${PYTHON:-python3}"

# open3d links libusb-1.0 and libgomp; OpenGL is not needed (we render with RaycastingScene).
need=()
for pkg in libusb-1.0-0 libgomp1; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  echo "setup: installing system packages: ${need[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi

"$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || {
  echo "setup: hiper needs Python 3.11 or newer; set PYTHON=python3.11" >&2; exit 1; }

stamp="$VENV/.hiper-installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  [ -x "$VENV/bin/python" ] || "$PYTHON" -m venv "$VENV"
  "$VENV/bin/python" -m pip install -q --upgrade pip
  "$VENV/bin/python" -m pip install -q -e ".[dev,mcp]"
  touch "$stamp"
fi
