#!/usr/bin/env bash
# Install everything the test-suite needs, then run the whole suite.
#   bash tools/test.sh [pytest args]        (e.g. -m "not slow" to skip the slowest locally)
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
# The three installs wait mostly on the network, so they run side by side (apt's and pip's
# downloads had taken turns); each one's failure stops the run with its own output.
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
apt_pid=""
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then
    echo "installing system packages: ${missing[*]}"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >/dev/null 2>"$logs/apt" &
    apt_pid=$!
  else
    echo "warning: missing system packages (${missing[*]}); run as root or install them" >&2
  fi
fi

# Bytecode is cached as Python does by default: where the environment forbids it, every one of the
# suite's hundreds of Python processes (CLI runs, batch and fuzz workers, the core install's
# commands) compiled every module it imports from source again.
unset PYTHONDONTWRITEBYTECODE
python -m pip install -q --disable-pip-version-check -e ".[test]" >"$logs/pip" 2>&1 &
pip_pid=$!
# every install is waited for, whichever fails, so none is left running and each says what it said
failed=()
npm ci --no-audit --no-fund --loglevel=error || failed+=(npm)
wait "$pip_pid" || failed+=(pip)
cat "$logs/pip" >&2
if [ -n "$apt_pid" ]; then
  wait "$apt_pid" || failed+=(apt-get)
  cat "$logs/apt" >&2
fi
if [ ${#failed[@]} -gt 0 ]; then
  echo "tools/test.sh: the install failed: ${failed[*]}" >&2
  exit 1
fi
# The whole suite, lint, types and the core-install smoke test included (tests/test_house.py), on
# every core (pytest-xdist; tests sharing a built asset, a browser page or a server stay on one
# worker: tests/conftest.py), with the 20 slowest printed and the suite's wall time last.
start=$(date +%s)
status=0
python -m pytest -n "${FISHGEN_TEST_WORKERS:-auto}" --dist loadgroup --no-loadscope-reorder --durations=20 "$@" || status=$?
echo "test suite: $(( $(date +%s) - start )) s wall on $(nproc) cores (pytest exit $status)"
exit $status
