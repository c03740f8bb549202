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
bad bloom "$scene" "$tmp/x.exr" --intensity 1e40
bad bloom "$scene" "$tmp/x.exr" --iterations 4294967296
bad bloom "$scene" "$tmp/x.exr" --knee -inf
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
# Truncated at many lengths, and single corrupted bytes through the header and the pixel data.
for len in 1 4 8 9 16 64 100 200 300 $((size - 1)); do
  head -c "$len" "$scene" >"$tmp/cut.exr"
  bad bloom "$tmp/cut.exr" "$tmp/x.exr"
done
for at in 8 12 20 40 80 120 200 300 $((size / 3)) $((size - 8)); do
  cp "$scene" "$tmp/flip.exr"
  printf '\xff' | dd of="$tmp/flip.exr" bs=1 seek="$at" conv=notrunc status=none
  "$GLINT" bloom "$tmp/flip.exr" "$tmp/x.exr" >"$tmp/out" 2>"$tmp/err"
  rc=$?
  # A flipped byte in pixel data may still decode: then it must succeed cleanly, else fail cleanly.
  if ((rc == 0)); then [[ ! -s "$tmp/err" ]] || fail "flip at $at: exit 0 with stderr"; else bad bloom "$tmp/flip.exr" "$tmp/x.exr"; fi
done
# Hostile headers: a data window of 10^9 pixels a side, and an attribute that declares 2 GiB.
python3 - "$scene" "$tmp" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], "rb").read())
i = data.index(b"dataWindow\0box2i\0") + len(b"dataWindow\0box2i\0") + 4
huge = bytearray(data); huge[i + 8:i + 12] = struct.pack("<i", 10**9)
open(sys.argv[2] + "/huge.exr", "wb").write(huge)
j = data.index(b"compression\0compression\0") + len(b"compression\0compression\0")
big = bytearray(data); big[j:j + 4] = struct.pack("<i", 2**31 - 1)
open(sys.argv[2] + "/bigattr.exr", "wb").write(big)
neg = bytearray(data); neg[j:j + 4] = struct.pack("<i", -5)
open(sys.argv[2] + "/negattr.exr", "wb").write(neg)
PY
bad bloom "$tmp/huge.exr" "$tmp/x.exr"
grep -qE 'larger than glint reads|exceeds the maximum width' "$tmp/err" || fail "huge data window: $(cat "$tmp/err")"
bad bloom "$tmp/bigattr.exr" "$tmp/x.exr"
grep -q 'corrupt header' "$tmp/err" || fail "2 GiB attribute: $(cat "$tmp/err")"
bad bloom "$tmp/negattr.exr" "$tmp/x.exr"
bad bloom "$scene" "$tmp/no/such/dir/x.exr"
bad bloom "$scene" "$tmp"
bad bloom "$scene" "$tmp/x.exr" --png "$tmp/no/such/dir/x.png"

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
bad lod --levels 18 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --aniso 100 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --bias nan "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --bias 17 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --atlas 70000x16 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --atlas 16 "$tmp/q.csv" "$tmp/x.csv"
bad lod --levels 13 --padding inf "$tmp/q.csv" "$tmp/x.csv"
: >"$tmp/empty.csv"
ok lod --levels 13 "$tmp/empty.csv" "$tmp/empty_out.csv"  # no queries, no rows: not an error
printf '1,2,3\n' >"$tmp/short.csv"
bad lod --levels 13 "$tmp/short.csv" "$tmp/x.csv"
printf '0.1,0,0,0.1,nan?,4,0,0\n' >"$tmp/junk.csv"
bad lod --levels 13 "$tmp/junk.csv" "$tmp/x.csv"

if ((failures)); then
  printf 'cli_test: %d failure(s)\n' "$failures" >&2
  exit 1
fi
echo "cli_test: ok"
