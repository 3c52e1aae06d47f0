#!/usr/bin/env bash
# The whole Kautham corpus (tools/get_kautham.sh --all calls this; see its --help):
#
#   tools/corpus/lay_out_all.sh REPO DEST MANIFEST
#
# For each tree the MANIFEST pins (its legacy_2012/ and current_2025/ rows name the commit),
# every file of the repository at that commit is written to DEST/<tree>/<repository path>,
# byte for byte. The repository may be a URL, a clone or a bare mirror; a mirror may lack some
# blobs (a partial copy): those, and files that are Git LFS pointers, are listed in
# DEST/SKIPPED.md and not laid out. DEST/ALL.md records the commits and the counts; the folder
# is assembled in a temporary one and moved into place only when complete.
set -eo pipefail
repo="$1"; dest="$2"; manifest="$3"
trees=(legacy_2012 current_2025)

if [ -f "$dest/ALL.md" ]; then
  echo "get_kautham.sh: the whole corpus is already at $dest (remove it to lay it out again)"
  exit 0
fi
if [ -e "$dest" ] && [ -n "$(ls -A "$dest" 2>/dev/null)" ]; then
  echo "get_kautham.sh: $dest exists and is not the whole corpus; move it away or give --dest" >&2
  exit 2
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
if git -C "$repo" rev-parse --git-dir >/dev/null 2>&1; then
  git_dir="$(git -C "$repo" rev-parse --absolute-git-dir)"
else
  echo "get_kautham.sh: cloning $repo (whole trees: every blob)"
  git clone --quiet --bare "$repo" "$work/kautham.git"
  git_dir="$work/kautham.git"
fi

lfs_head="version https://git-lfs.github.com/spec/v1"
{
  echo "# Files of the pinned trees not laid out"
  echo
  echo "| tree | repository path | why |"
  echo "|---|---|---|"
} > "$work/SKIPPED.md"
{
  echo "# The whole Kautham corpus (tools/get_kautham.sh --all)"
  echo
  echo "Every file of iocroblab/kautham at the commits $(basename "$manifest") pins, under the"
  echo "tree's name; SKIPPED.md lists the files whose content was not available."
  echo
  echo "| tree | commit | files laid out | skipped |"
  echo "|---|---|---|---|"
} > "$work/ALL.md"
mkdir -p "$work/corpus"
for tree in "${trees[@]}"; do
  commit="$(grep -E "^\| $tree/" "$manifest" | head -1 | cut -d'|' -f4 | grep -oE '[0-9a-f]{40}' || true)"
  if [ -z "$commit" ]; then
    echo "get_kautham.sh: $manifest pins no commit for $tree/" >&2
    exit 1
  fi
  if ! git --git-dir="$git_dir" cat-file -e "$commit^{tree}" 2>/dev/null; then
    echo "get_kautham.sh: $repo has no commit $commit (the $tree tree)" >&2
    exit 1
  fi
  laid=0; skipped=0
  # mode type object size<TAB>path, NUL-terminated (paths may hold spaces)
  while IFS= read -r -d '' entry; do
    meta="${entry%%$'\t'*}"; path="${entry#*$'\t'}"
    read -r mode type object size <<< "$meta"
    target="$work/corpus/$tree/$path"
    if [ "$type" != blob ]; then
      printf '| %s | %s | a %s (mode %s), not a file |\n' "$tree" "$path" "$type" "$mode" >> "$work/SKIPPED.md"
      skipped=$((skipped + 1)); continue
    fi
    if ! git --git-dir="$git_dir" cat-file -e "$object" 2>/dev/null; then
      printf '| %s | %s | absent from the repository copy (blob %s) |\n' "$tree" "$path" "$object" >> "$work/SKIPPED.md"
      skipped=$((skipped + 1)); continue
    fi
    mkdir -p "$(dirname "$target")"
    if [ "$mode" = 120000 ]; then
      ln -s "$(git --git-dir="$git_dir" cat-file blob "$object")" "$target"
    else
      git --git-dir="$git_dir" cat-file blob "$object" > "$target"
      if [ "$size" -lt 1024 ] && [ "$(head -c ${#lfs_head} "$target" | tr -d '\0')" = "$lfs_head" ]; then
        rm -f "$target"
        printf '| %s | %s | a Git LFS pointer (the content is not in the repository) |\n' "$tree" "$path" >> "$work/SKIPPED.md"
        skipped=$((skipped + 1)); continue
      fi
      if [ "$(stat -c %s "$target")" != "$size" ]; then
        echo "get_kautham.sh: $tree/$path has $(stat -c %s "$target") bytes, the repository says $size" >&2
        exit 1
      fi
      [ "$mode" = 100755 ] && chmod +x "$target"
    fi
    laid=$((laid + 1))
  done < <(git --git-dir="$git_dir" ls-tree -r -l -z "$commit")
  printf '| %s | %s | %d | %d |\n' "$tree" "$commit" "$laid" "$skipped" >> "$work/ALL.md"
  echo "get_kautham.sh: $tree: $laid files laid out, $skipped skipped (SKIPPED.md)"
done
mv "$work/SKIPPED.md" "$work/ALL.md" "$work/corpus/"
mkdir -p "$(dirname "$dest")"
rm -rf "$dest"
mv "$work/corpus" "$dest"
echo "get_kautham.sh: the whole corpus is in $dest"
