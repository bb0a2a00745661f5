#!/usr/bin/env bash
# The core install alone (no test extra) runs every command on every shipped kind of input without a
# traceback: catches a runtime dependency that only the test extra happened to bring in.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# no pip of its own (ensurepip took 5 s of the suite's time): this pip installs into it, and compiles
# nothing ahead (byte-compiling all of numpy and scipy took 5 of the install's 13 s; the commands
# compile what they import)
# nor does the environment stop the commands from keeping what they compile (PYTHONDONTWRITEBYTECODE
# had each of them compile numpy, scipy and trimesh from source again: 40 s, not 27)
unset PYTHONDONTWRITEBYTECODE
python -m venv --without-pip "$work/venv"
python -m pip --python "$work/venv/bin/python" install -q --no-compile --disable-pip-version-check "$root"
fishgen="$work/venv/bin/fishgen"
cd "$work"
run() {  # run a command; fail on a non-zero exit or any traceback on stderr
  if ! "$@" >out.txt 2>err.txt || grep -q Traceback err.txt; then
    echo "core install: '$*' failed:" >&2; cat err.txt >&2; exit 1
  fi
}
run "$fishgen" build "$root/params/bonybream.txt" -o fish.obj
run "$fishgen" build "$root/params/bonybream.txt" -o fish.ply
run "$fishgen" build "$root/params/bonybream.txt" -o fish.glb
run "$fishgen" clouds "$root/params/clouds/table_4_3.awn" -o cloud.ply
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n# caf\xe9\nf 1 2 3\n' > latin1.obj   # one Latin-1 byte, no normals
for input in fish.obj fish.ply fish.glb cloud.ply latin1.obj "$root/params/bonybream.txt"; do
  run "$fishgen" preview "$input" -o preview.png --size 64x48
done
run "$fishgen" view fish.glb --no-serve -o page.html
run "$fishgen" species --random --seed 1 -o sampled.txt
run "$fishgen" preview sampled.txt --view side --ortho --background transparent --size 256x128 -o photo.png
run "$fishgen" texture photo.png -s sampled.txt -o fromphoto.txt --fit-shape --compare compare.png
run "$fishgen" clouds "$root/params/clouds/sky.awa" -o texture-sky.glb
run "$fishgen" school "$root/params/bait-ball.toml" --frames 20 -o ball.glb
run "$fishgen" sky --mode thin --particles 2000 -o sky.glb
run "$fishgen" build "$root/params/bonybream.txt" --lods 16x12,8x6 --merge --clips swim,burst -o engine.glb
# the serving commands need a browser or a Ctrl-C; their one-line refusals need neither
"$fishgen" fly missing.awn >out.txt 2>err.txt && { echo "core install: fly took a missing file" >&2; exit 1; }
grep -q Traceback err.txt && { echo "core install: fly:" >&2; cat err.txt >&2; exit 1; }
"$fishgen" fly sky.glb --headless >out.txt 2>err.txt || grep -q "fishgen\[fly\]\|Chromium\|playwright" err.txt || {
  echo "core install: fly --headless without its extra:" >&2; cat err.txt >&2; exit 1; }
echo "core install: every command ran without a traceback"
