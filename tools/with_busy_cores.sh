#!/usr/bin/env bash
# Runs a command while one busy loop spins on each core, then stops the loops: `make
# test-stress` runs the suite this way, to find tests that wait for a time instead of an event.
#   tools/with_busy_cores.sh COMMAND [ARG...]    exits with COMMAND's status
set -eo pipefail
loops=()
stop_loops() { [ "${#loops[@]}" -eq 0 ] || kill "${loops[@]}" 2>/dev/null || true; }
trap stop_loops EXIT
for _ in $(seq "$(nproc)"); do
  ( while :; do :; done ) &
  loops+=("$!")
done
echo "with_busy_cores.sh: ${#loops[@]} busy loops running" >&2
status=0
"$@" || status=$?
exit "$status"
