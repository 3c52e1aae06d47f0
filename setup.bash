# Source this file (bash) to get Odin's environment: the venv, the catkin workspace, the
# Kautham data path and off-screen rendering. Works with `set -u` active in the caller.
_odin_root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ ! -f "$_odin_root/build/ws/devel/setup.bash" ]; then
  echo "Odin is not built yet: run 'make setup' in $_odin_root" >&2
  return 1 2>/dev/null || exit 1
fi
_odin_had_u=0; case $- in *u*) _odin_had_u=1; set +u;; esac
# shellcheck disable=SC1091
source "$_odin_root/.venv/bin/activate"
# shellcheck disable=SC1091
source "$_odin_root/build/ws/devel/setup.bash"
export ODIN_ROOT="$_odin_root"
export ODIN_KAUTHAM_DIR="${ODIN_KAUTHAM_DIR:-$(cd "$_odin_root/.." && pwd)/shared/kautham}"
export PYOPENGL_PLATFORM=osmesa
# ROS 1 has no authentication: whoever reaches a node's port can call its services. Unless the
# user names an address (ROS_IP or ROS_HOSTNAME, docs/SECURITY.md), nodes listen and advertise
# on the loopback address only, and the master is looked for there.
if [ -z "${ROS_IP:-}${ROS_HOSTNAME:-}" ]; then
  export ROS_IP=127.0.0.1
  export ROS_MASTER_URI="${ROS_MASTER_URI:-http://127.0.0.1:11311}"
fi
[ "$_odin_had_u" = 1 ] && set -u
unset _odin_had_u
