#!/usr/bin/env bash
# Lays out the Kautham corpus that Odin's tests, demo and experiments use: real problem, robot,
# geometry and control files of the public Kautham repository (iocroblab/kautham, GPL-2.0+),
# each taken byte for byte at the commit tools/kautham/MANIFEST.md pins for it, in the layout
# ODIN_KAUTHAM_DIR expects (the MANIFEST's "local path" column).
#
#   tools/get_kautham.sh [--all] [--repo URL_OR_PATH] [--dest DIR] [--manifest FILE]
#
#   --all       the whole corpus instead: every file of the repository at each commit the
#               MANIFEST pins a tree for (legacy_2012/ and current_2025/, the repository's
#               whole tree under each), for `make corpus` (tools/corpus/run.py). A file whose
#               content the repository does not hold (absent from a mirror, or a Git LFS
#               pointer) is listed in SKIPPED.md there and not laid out.
#   --repo      a clone or mirror of iocroblab/kautham (bare or not), or its URL
#               (default: https://github.com/iocroblab/kautham.git)
#   --dest      where the corpus goes (default: $ODIN_KAUTHAM_DIR, else ../shared/kautham
#               beside this clone, which is where setup.bash looks; with --all:
#               $ODIN_KAUTHAM_ALL_DIR, else ../shared/kautham_all beside it)
#   --manifest  the table of files (default: tools/kautham/MANIFEST.md)
#
# Every file's size is checked against the MANIFEST (--all: against the repository's tree); the
# corpus is assembled in a temporary folder and moved into place only when complete, so a
# failure leaves nothing half-done.
set -eo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
manifest="$root/tools/kautham/MANIFEST.md"
repo="https://github.com/iocroblab/kautham.git"
dest=""
all=0

while [ $# -gt 0 ]; do
  case "$1" in
    --repo) repo="$2"; shift 2 ;;
    --dest) dest="$2"; shift 2 ;;
    --manifest) manifest="$2"; shift 2 ;;
    --all) all=1; shift ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) echo "get_kautham.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

if [ -z "$dest" ]; then
  if [ "$all" = 1 ]; then
    dest="${ODIN_KAUTHAM_ALL_DIR:-$(cd "$root/.." && pwd)/shared/kautham_all}"
  else
    dest="${ODIN_KAUTHAM_DIR:-$(cd "$root/.." && pwd)/shared/kautham}"
  fi
fi
if [ "$all" = 1 ]; then
  exec "$root/tools/corpus/lay_out_all.sh" "$repo" "$dest" "$manifest"
fi

if [ -f "$dest/MANIFEST.md" ] && cmp -s "$dest/MANIFEST.md" "$manifest"; then
  echo "get_kautham.sh: the corpus is already at $dest"
  exit 0
fi
if [ -e "$dest" ] && [ -n "$(ls -A "$dest" 2>/dev/null)" ]; then
  echo "get_kautham.sh: $dest exists and is not this corpus; move it away or give --dest" >&2
  exit 2
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "get_kautham.sh: cloning $repo"
if ! git clone --quiet --no-checkout --filter=blob:none "$repo" "$work/kautham" 2>/dev/null; then
  git clone --quiet --no-checkout "$repo" "$work/kautham"
fi

# rows of the MANIFEST's table: | local path | repo | commit | repo path | bytes | role |
count=0
while IFS='|' read -r _ local_path repo_name commit repo_path bytes _; do
  local_path="$(echo "$local_path" | xargs)"; repo_path="$(echo "$repo_path" | xargs)"
  commit="$(echo "$commit" | grep -oE '[0-9a-f]{40}' | head -1)"; bytes="$(echo "$bytes" | xargs)"
  target="$work/corpus/$local_path"
  mkdir -p "$(dirname "$target")"
  if ! git -C "$work/kautham" show "$commit:$repo_path" > "$target" 2>/dev/null; then
    echo "get_kautham.sh: $repo has no $repo_path at $commit (MANIFEST row $local_path)" >&2
    exit 1
  fi
  size="$(stat -c %s "$target")"
  if [ "$size" != "$bytes" ]; then
    echo "get_kautham.sh: $local_path has $size bytes, the MANIFEST says $bytes" >&2
    exit 1
  fi
  count=$((count + 1))
done < <(grep -E '^\| [^ |]+ \| iocroblab/kautham \| [0-9a-f]{40}' "$manifest")

if [ "$count" -eq 0 ]; then
  echo "get_kautham.sh: no file rows in $manifest" >&2
  exit 1
fi
cp "$manifest" "$work/corpus/MANIFEST.md"
mkdir -p "$(dirname "$dest")"
rm -rf "$dest"
mv "$work/corpus" "$dest"
echo "get_kautham.sh: $count files laid out in $dest"
