#!/usr/bin/env bash
# Smoke test of the glint command: the happy paths write their files with nothing on stderr, and
# every bad flag or bad file exits 2 with exactly one line "glint: error: ..." on stderr (never a
# crash, a stack trace or CLI11's own exit codes).
# Usage: tests/cli_test.sh path/to/glint   (glint.sh test runs it; so can ctest)
set -uo pipefail

GLINT="${1:?usage: cli_test.sh path/to/glint}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
failures=0

fail() { printf 'FAIL: %s\n' "$*" >&2; failures=$((failures + 1)); }

# ok ARGS...: exit 0, nothing on stderr.
ok() {
  "$GLINT" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if ((rc != 0)) || [[ -s "$tmp/err" ]]; then
    fail "glint $* -> exit $rc; stderr:"
    cat "$tmp/err" >&2
  fi
}

# bad ARGS...: exit 2, exactly one stderr line starting "glint: error: ".
bad() {
  "$GLINT" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$? lines
  lines=$(wc -l <"$tmp/err")
  if ((rc != 2)) || ((lines != 1)) || ! grep -q '^glint: error: ' "$tmp/err"; then
    fail "glint $* -> exit $rc, $lines stderr line(s):"
    cat "$tmp/err" >&2
  fi
}

expect_file() { [[ -s "$1" ]] || fail "missing or empty output $1"; }

# Happy paths.
ok --help
ok bloom --help
ok --version
ok devices
grep -q '^index' "$tmp/out" || fail "glint devices printed no table"
ok demo --size 96x64 --out "$tmp/demo"
expect_file "$tmp/demo/scene.exr"
expect_file "$tmp/demo/bloom.exr"
expect_file "$tmp/demo/bloom.png"
grep -q 'total' "$tmp/out" || grep -q 'not available' "$tmp/out" || fail "glint demo printed no stage times"
scene="$tmp/demo/scene.exr"
for filter in cod13 dual gauss9; do
  ok bloom "$scene" "$tmp/$filter.exr" --png "$tmp/$filter.png" --filter "$filter" --threshold 0.8 --knee 0.3 \
    --intensity 0.5 --iterations 4 --radius 1.5
  expect_file "$tmp/$filter.exr"
  expect_file "$tmp/$filter.png"
done
ok bloom "$scene" "$tmp/fp32.exr" --fp32
ok bloom "$tmp/cod13.exr" "$tmp/again.exr"  # its own output is valid input
ok demo --size 1x1 --out "$tmp/tiny"
grep -q 'clamped' "$tmp/out" || fail "a 1x1 demo did not report clamped levels"

# Bad command lines.
bad
bad frobnicate
bad bloom
bad bloom "$scene"
bad bloom "$scene" "$tmp/x.exr" extra
bad bloom "$scene" "$tmp/x.exr" --no-such-flag
bad bloom "$scene" "$tmp/x.exr" --threshold
bad bloom "$scene" "$tmp/x.exr" --threshold abc
bad bloom "$scene" "$tmp/x.exr" --threshold -1
bad bloom "$scene" "$tmp/x.exr" --threshold nan
bad bloom "$scene" "$tmp/x.exr" --knee 2
bad bloom "$scene" "$tmp/x.exr" --intensity -0.5
bad bloom "$scene" "$tmp/x.exr" --iterations 0
bad bloom "$scene" "$tmp/x.exr" --iterations 99
bad bloom "$scene" "$tmp/x.exr" --iterations -1
bad bloom "$scene" "$tmp/x.exr" --radius 0.1
bad bloom "$scene" "$tmp/x.exr" --radius inf
bad bloom "$scene" "$tmp/x.exr" --filter box
bad bloom "$scene" "$tmp/x.exr" --png "$tmp/x.png" --exposure 0
bad bloom "$scene" "$tmp/x.exr" --device 99
bad bloom "$scene" "$tmp/x.exr" --device no-such-gpu
bad demo --size 0x10 --out "$tmp/d"
bad demo --size 10 --out "$tmp/d"
bad demo --size 20000x10 --out "$tmp/d"
bad demo --exposure -1 --out "$tmp/d"
bad demo --out "$scene"  # a file, not a directory

# Bad files.
bad bloom "$tmp/missing.exr" "$tmp/x.exr"
bad bloom "$tmp" "$tmp/x.exr"
: >"$tmp/empty.exr"
bad bloom "$tmp/empty.exr" "$tmp/x.exr"
head -c 4096 /dev/urandom >"$tmp/noise.exr"
bad bloom "$tmp/noise.exr" "$tmp/x.exr"
bad bloom "$tmp/cod13.png" "$tmp/x.exr"
size=$(stat -c %s "$scene")
head -c $((size / 2)) "$scene" >"$tmp/half.exr"
bad bloom "$tmp/half.exr" "$tmp/x.exr"
head -c 40 "$scene" >"$tmp/header.exr"
bad bloom "$tmp/header.exr" "$tmp/x.exr"
bad bloom "$scene" "$tmp/no/such/dir/x.exr"
bad bloom "$scene" "$tmp"
bad bloom "$scene" "$tmp/x.exr" --png "$tmp/no/such/dir/x.png"

# glint blur / gauss: level files at 1/2, 1/4, 1/8 of the 96x64 scene; the method is reported.
ok blur "$scene" "$tmp/bp" --sigmas 0.8,1.2,2
for k in 1 2 3; do expect_file "$tmp/bp.blur$k.exr"; done
grep -q 'blur3.exr (12x8' "$tmp/out" || fail "glint blur level 3 size: $(grep blur3 "$tmp/out")"
for method in auto separable pyramid dual; do
  ok gauss "$scene" "$tmp/g_$method.exr" --sigma 5 --method "$method"
  expect_file "$tmp/g_$method.exr"
  grep -q '^method: ' "$tmp/out" || fail "glint gauss --method $method printed no method"
  grep -q 'expected relative L2 error' "$tmp/out" || fail "glint gauss --method $method printed no error"
done
ok gauss "$scene" "$tmp/g_lin.exr" --sigma 1.5 --method separable --linear --fp32
bad blur "$scene" "$tmp/bp" --sigmas 1,2
bad blur "$scene" "$tmp/bp" --sigmas 1,2,9
bad blur "$scene" "$tmp/bp" --sigmas a,b,c
bad blur "$tmp/missing.exr" "$tmp/bp"
bad blur "$scene" "$tmp/no/such/dir/bp"
bad gauss "$scene" "$tmp/g.exr"
bad gauss "$scene" "$tmp/g.exr" --sigma 0.1
bad gauss "$scene" "$tmp/g.exr" --sigma 100
bad gauss "$scene" "$tmp/g.exr" --sigma nan
bad gauss "$scene" "$tmp/g.exr" --sigma 2 --method box
bad gauss "$scene" "$tmp/g.exr" --sigma 2 --max-error 0
bad gauss "$scene" "$tmp/g.exr" --sigma 2 --method dual --linear
bad gauss "$tmp/noise.exr" "$tmp/g.exr" --sigma 2

# glint lod: every row comes back with a lod column; the level of a 256x256 tile seen at 4 texels
# per pixel is 2 (log2 4), whatever the atlas.
printf 'dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y\n0.015625,0,0,0.015625,256,256,0,0\n0.015625,0,0,0.015625,256,256,3840,3840\n' >"$tmp/q.csv"
ok lod --atlas 4096x4096 --levels 13 "$tmp/q.csv" "$tmp/lod.csv"
[[ "$(sed -n 2p "$tmp/lod.csv")" == "0.015625,0,0,0.015625,256,256,0,0,2.000000" ]] || fail "lod row 1: $(sed -n 2p "$tmp/lod.csv")"
[[ "$(sed -n 3p "$tmp/lod.csv" | cut -d, -f9)" == "2.000000" ]] || fail "lod row 2: $(sed -n 3p "$tmp/lod.csv")"
ok lod --levels 13 --aniso 4 --bias 0.5 --padding 8 "$tmp/q.csv" "$tmp/lod2.csv"
bad lod --levels 0 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --aniso 0.5 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --padding -3 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --atlas 0x4 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 "$tmp/missing.csv" "$tmp/x.csv"
printf '1,2,3\n' >"$tmp/short.csv"
bad lod --levels 13 "$tmp/short.csv" "$tmp/x.csv"
printf '0.1,0,0,0.1,nan?,4,0,0\n' >"$tmp/junk.csv"
bad lod --levels 13 "$tmp/junk.csv" "$tmp/x.csv"

if ((failures)); then
  printf 'cli_test: %d failure(s)\n' "$failures" >&2
  exit 1
fi
echo "cli_test: ok"
