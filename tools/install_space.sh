#!/usr/bin/env bash
# Builds and installs the stack into build/install_ws/install with `catkin_make install`, from
# a bare environment (the venv's Python first on PATH; nothing of the devel space or the source
# tree on PYTHONPATH): the install space tests/system/test_install_space.py uses with nothing
# of the source tree in sight. The build folder stays between runs (a rebuild compiles only
# what changed); the install folder is emptied first, so that a file only an old build
# installed cannot stand in for a missing install rule. Called by tools/build.sh (make setup)
# and by the test, which holds build/install_ws.lock meanwhile.
set -eo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ws="$root/build/install_ws"
venv="$root/.venv/bin"
mkdir -p "$ws/src"
ln -sfn "$root/Odin" "$ws/src/Odin"
rm -rf "$ws/install"
if ! env -i HOME="${HOME:-/root}" PATH="$venv:/usr/bin:/bin" \
    catkin_make -C "$ws" -DPYTHON_EXECUTABLE="$venv/python" -DCATKIN_ENABLE_TESTING=OFF \
    -DCMAKE_INSTALL_PREFIX="$ws/install" install > "$root/build/install_space.log" 2>&1; then
  tail -40 "$root/build/install_space.log" >&2
  exit 1
fi
echo "install_space.sh: installed in $ws/install"
