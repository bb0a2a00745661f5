#!/usr/bin/env bash
# Install everything the test-suite needs, then run the whole suite.
#   bash tools/test.sh [pytest args]
# System packages (software OpenGL for previews, Chromium for the viewer test)
# come from apt when running as root and they are missing; Python packages
# from the project's `test` extra; the Khronos glTF-Validator and three.js from npm.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 chromium godot3-server)
missing=()
for pkg in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then
    echo "installing system packages: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    echo "warning: missing system packages (${missing[*]}); run as root or install them" >&2
  fi
fi

python -m pip install -q --disable-pip-version-check -e ".[test]"
npm ci --no-audit --no-fund --loglevel=error
bash tools/core_smoke.sh
python -m ruff check fishgen
python -m mypy
python -m pytest "$@"
