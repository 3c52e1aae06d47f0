#!/usr/bin/env bash
# Odin's one install recipe, used by `make setup`, CI and docker/Dockerfile alike.
# Idempotent. Needs root for apt (skipped when every package is already installed).
#   1. apt packages from tools/apt-packages.txt
#   2. a venv in .venv made from Debian's /usr/bin/python3 with --system-site-packages
#   3. pinned pip requirements (tools/requirements.txt)
#   4. the catkin build of Odin/ (workspace in build/ws), including the compiled ODE extension
#   --bench: only the benchmark venv .venv-bench (tools/requirements-bench.txt: MuJoCo and
#   PyBullet, the peers of make bench), apart from Odin's so that make test never needs them
set -eo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

if [ "$1" = "--bench" ]; then
  bench_venv="$root/.venv-bench"
  if [ ! -x "$bench_venv/bin/python" ]; then
    echo "install.sh: creating venv $bench_venv"
    /usr/bin/python3 -m venv "$bench_venv"
  fi
  stamp="$bench_venv/.requirements.sha"
  want="$(sha256sum tools/requirements-bench.txt | cut -d' ' -f1)"
  if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    "$bench_venv/bin/python" -m pip install -q --disable-pip-version-check \
      -r tools/requirements-bench.txt
    echo "$want" > "$stamp"
  fi
  exit 0
fi

mapfile -t packages < <(sed -e 's/#.*//' -e '/^\s*$/d' tools/apt-packages.txt)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "install.sh: missing Debian packages (${missing[*]}); run as root" >&2
    exit 1
  fi
  echo "install.sh: apt-get install ${#missing[@]} packages"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

venv="$root/.venv"
if [ ! -x "$venv/bin/python" ]; then
  echo "install.sh: creating venv $venv"
  /usr/bin/python3 -m venv --system-site-packages "$venv"
fi
stamp="$venv/.requirements.sha"
want="$(sha256sum tools/requirements.txt | cut -d' ' -f1)"
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r tools/requirements.txt
  echo "$want" > "$stamp"
fi

# shellcheck disable=SC1091
source "$venv/bin/activate"
"$root/tools/build.sh"
echo "install.sh: done. Now: source $root/setup.bash"
