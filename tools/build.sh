#!/usr/bin/env bash
# Builds the catkin workspace build/ws (its src/Odin is a link to the stack) with the venv's
# Python, and the install space build/install_ws (tools/install_space.sh). Called by
# tools/install.sh; run it again after editing .msg/.srv or the C extension.
set -eo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ws="$root/build/ws"
mkdir -p "$ws/src"
ln -sfn "$root/Odin" "$ws/src/Odin"
python="$root/.venv/bin/python"
force=()
# catkin caches the environment of its first configure: configure afresh once so that the
# venv's python and an empty PYTHONPATH are not frozen into the cache (platform notes).
if [ ! -f "$ws/build/.odin-configured" ]; then force=(--force-cmake); fi
# catkin_make runs Python tools; keep the venv first on PATH.
export PATH="$root/.venv/bin:$PATH"
make_workspace() {
  catkin_make -C "$ws" "$@" -DPYTHON_EXECUTABLE="$python" -DCATKIN_ENABLE_TESTING=OFF \
    > "$root/build/catkin_make.log" 2>&1
}
if ! make_workspace "${force[@]}"; then
  # a .msg that gained a dependency (a field of another message type) needs cmake again
  if grep -q "Please rerun cmake" "$root/build/catkin_make.log" && make_workspace --force-cmake
  then :; else tail -40 "$root/build/catkin_make.log" >&2; exit 1; fi
fi
touch "$ws/build/.odin-configured"
# byte-compile the stack and the generated messages now: a process that cannot write them
# (PYTHONDONTWRITEBYTECODE, a read-only tree) would compile ~100 modules on every start
# (~0.45 s of each load_problem)
"$python" -m compileall -q "$root/Odin" "$ws/devel/lib" > /dev/null
echo "build.sh: catkin workspace built in $ws"
# the install space make test checks (tests/system/test_install_space.py), built now so that a
# test run recompiles only what changed (held by the test's lock: two at once would collide)
(flock 9; "$root/tools/install_space.sh") 9> "$root/build/install_ws.lock"
