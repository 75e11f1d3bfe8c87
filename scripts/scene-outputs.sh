#!/usr/bin/env bash
# Writes what `dupin` produces for every scene and a few fixed inputs into DIR, so that two
# builds can be compared byte for byte (`diff -r DIR_A DIR_B`). Reports drop `seconds`, the
# only field that depends on the machine.
#
#   scripts/scene-outputs.sh path/to/dupin DIR
#   scripts/scene-outputs.sh --compare BASE_REV DIR   # builds BASE_REV and HEAD, compares them
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"

if [[ "${1:-}" == "--compare" ]]; then
  base="$2"; out="$3"
  rm -rf "$out"; mkdir -p "$out"
  wt="$out/base-tree"
  git -C "$root" worktree add --detach "$wt" "$base" >/dev/null
  trap 'git -C "$root" worktree remove --force "$wt"' EXIT
  # The old tree may not have this script: use ours for both builds. The base builds into a
  # target folder of its own: sharing ours, cargo would leave the base binary in
  # target/release when the HEAD build that follows finds nothing to compile.
  (cd "$wt" && CARGO_TARGET_DIR="$out/base-target" cargo build --release -q -p dupin-cli)
  cp "$out/base-target/release/dupin" "$out/dupin-base"
  (cd "$root" && cargo build --release -q -p dupin-cli)
  "$0" "$out/dupin-base" "$out/base"
  "$0" "$root/target/release/dupin" "$out/head"
  if diff -r "$out/base" "$out/head" >"$out/diff.txt"; then
    echo "scene outputs identical: $(ls "$out/head" | wc -l) files"
  else
    echo "scene outputs differ (see $out/diff.txt):"; head -20 "$out/diff.txt"; exit 1
  fi
  exit 0
fi

bin="$1"; dir="$2"
mkdir -p "$dir"
strip_seconds() { python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); d.pop("seconds",None); print(json.dumps(d,sort_keys=True,indent=1))' "$1" >"$1.tmp" && mv "$1.tmp" "$1"; }
run() { # name, then the dupin arguments (without --out/--report)
  local name="$1"; shift
  "$bin" "$@" --out "$dir/$name.obj" --report "$dir/$name.json" >"$dir/$name.stdout" 2>"$dir/$name.stderr" || echo "exit $?" >>"$dir/$name.stderr"
  sed -i -E 's/[0-9.]+ ?(s|ms)\b/T/g' "$dir/$name.stdout"
  [[ -f "$dir/$name.json" ]] && strip_seconds "$dir/$name.json"
  true
}
for s in $("$bin" phex --list-scenes); do run "phex-$s" phex --scene "$s"; done
for s in $("$bin" pq --list-scenes); do run "pq-$s" pq --scene "$s"; done
run phex-torus-free phex --surface torus --size 0.4 --iterations 5
run phex-sphere-prescribed phex --surface sphere --method prescribed --size 0.35 --no-optimize
for m in planar conical circular; do
  run "planarize-$m" planarize --input "$dir/pq-pq-catmull-clark.obj" --mode "$m" --max-iterations 30
done
"$bin" offset --input "$dir/pq-conical-station.obj" --distance 0.1 --out "$dir/offset.obj" \
  --support "$dir/support.obj" >"$dir/offset.stdout" 2>&1 || echo "exit $?" >>"$dir/offset.stdout"
sed -i -E 's/[0-9.]+ ?(s|ms)\b/T/g' "$dir/offset.stdout"
python3 - "$dir/points.txt" "$dir/segments.txt" <<'PY'
import random, sys
r = random.Random(7)
with open(sys.argv[1], "w") as f:
    for _ in range(300): f.write(f"{r.uniform(0, 10)!r} {r.uniform(0, 10)!r}\n")
    f.write("0 0\n10 0\n10 10\n0 10\n")
with open(sys.argv[2], "w") as f:
    f.write("300 301\n301 302\n302 303\n303 300\n")
PY
for m in simple extended; do
  run "hexd-$m" hexdelaunay --points "$dir/points.txt" --mode "$m"
  run "hexd-$m-pslg" hexdelaunay --points "$dir/points.txt" --segments "$dir/segments.txt" --mode "$m"
done
for at in 0.3,0.2 1,2; do
  for s in sphere torus hyperboloid; do
    "$bin" surface-info --surface "$s" --at "$at" >"$dir/info-$s-$at.json" 2>&1 || true
  done
done
echo "wrote $(ls "$dir" | wc -l) files to $dir"
