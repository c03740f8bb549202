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
for f in scene.exr depth.exr lights.json flares.exr bloom.exr bloom.png; do expect_file "$tmp/demo/$f"; done
grep -q '^flares: .*lights: 14 total, 2 frustum-culled, 3 occluded, 8 visible (0 overflow), 1 disabled' "$tmp/out" ||
  fail "glint demo flare statistics: $(grep '^flares' "$tmp/out")"
grep -q 'flare raster' "$tmp/out" || grep -q 'not available' "$tmp/out" || fail "glint demo printed no flare stage"
grep -q 'total' "$tmp/out" || grep -q 'not available' "$tmp/out" || fail "glint demo printed no stage times"
scene="$tmp/demo/scene.exr"
for filter in cod13 dual gauss9; do
  ok bloom "$scene" "$tmp/$filter.exr" --png "$tmp/$filter.png" --filter "$filter" --threshold 0.8 --knee 0.3 \
    --intensity 0.5 --iterations 4 --radius 1.5
  expect_file "$tmp/$filter.exr"
  expect_file "$tmp/$filter.png"
done
ok bloom "$scene" "$tmp/fp32.exr" --fp32
ok bloom "$scene" "$tmp/guard.exr" --firefly-guard karis --max-brightness 500 --level0-height 100
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
bad bloom "$scene" "$tmp/x.exr" --firefly-guard on
bad bloom "$scene" "$tmp/x.exr" --level0-height 4
bad bloom "$scene" "$tmp/x.exr" --max-brightness 9000
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
bad demo --size 8x8 --out "$tmp/d" --preset sparkly
ok demo --size 8x8 --out "$tmp/dp" --preset DEFAULT  # the presets of `flare`, parsed by the same code
grep -q '^flares: preset DEFAULT' "$tmp/out" || fail "demo --preset default: $(grep '^flares' "$tmp/out")"

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
bad bloom "$scene" "$tmp/x.exr" --png "$tmp/./x.exr"
grep -q 'OUT and --png are the same file' "$tmp/err" || fail "bloom OUT = --png: $(cat "$tmp/err")"

# glint blur / gauss: level files at 1/2, 1/4, 1/8 of the 96x64 scene; the method is reported.
ok blur "$scene" "$tmp/bp" --sigmas 0.8,1.2,2
for k in 1 2 3; do expect_file "$tmp/bp.blur$k.exr"; done
grep -q 'blur3.exr (12x8' "$tmp/out" || fail "glint blur level 3 size: $(grep blur3 "$tmp/out")"
for method in auto separable pyramid dual; do
  ok gauss "$scene" "$tmp/g_$method.exr" --sigma 5 --method "$method"
  expect_file "$tmp/g_$method.exr"
  grep -q '^method: ' "$tmp/out" || fail "glint gauss --method $method printed no method"
  grep -q 'expected relative L2 error' "$tmp/out" || fail "glint gauss --method $method printed no error"
  # Every method's printed error covers the whole image, borders included (docs/BLUR.md "Borders").
  grep -q 'expected relative L2 error [0-9.e+-]* over the whole image' "$tmp/out" ||
    fail "glint gauss --method $method does not say its bound is for the whole image"
  if grep -q 'interior' "$tmp/out"; then fail "glint gauss --method $method still limits its bound to the interior"; fi
done
ok gauss "$scene" "$tmp/g_lin.exr" --sigma 1.5 --method separable --linear --fp32
# --fp32 writes 32-bit float channels, the default half: the pixel type of each channel in the
# header's chlist (OpenEXR file layout: name, NUL, int32 type with 1 = HALF, 2 = FLOAT).
ok gauss "$scene" "$tmp/g_f32.exr" --sigma 3 --method separable --fp32
exr_types() {
  python3 - "$1" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
i = data.index(b'channels\0chlist\0') + len(b'channels\0chlist\0')
size = struct.unpack_from('<i', data, i)[0]
body, types, j = data[i + 4:i + 4 + size], [], 0
while body[j] != 0:
    end = body.index(b'\0', j)
    types.append(struct.unpack_from('<i', body, end + 1)[0])
    j = end + 1 + 16
print(' '.join(str(t) for t in types))
PY
}
[ "$(exr_types "$tmp/g_f32.exr")" = "2 2 2 2" ] || fail "glint gauss --fp32 wrote channel types $(exr_types "$tmp/g_f32.exr")"
[ "$(exr_types "$tmp/g_separable.exr")" = "1 1 1 1" ] || fail "glint gauss wrote channel types $(exr_types "$tmp/g_separable.exr")"
ok bloom "$scene" "$tmp/b_f32.exr" --fp32
[ "$(exr_types "$tmp/b_f32.exr")" = "2 2 2 2" ] || fail "glint bloom --fp32 wrote channel types $(exr_types "$tmp/b_f32.exr")"
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
# bad_csv 'TEXT' 'EXPECTED PART OF THE MESSAGE': every data row is evaluated or rejected by line.
bad_csv() {
  printf '%s' "$1" >"$tmp/bad.csv"
  bad lod --levels 13 "$tmp/bad.csv" "$tmp/x.csv"
  grep -qF -- "$2" "$tmp/err" || fail "bad CSV '$1': message lacks '$2': $(cat "$tmp/err")"
}
bad_csv $'0.1,0,0,0.1,256,256,0,0\n0.1,0,0,0.1,nan,256,0,0\n' 'line 2: field 5 (tex_w)'
bad_csv $'0.1,0,0,0.1,256,inf,0,0\n' 'line 1: field 6 (tex_h)'
bad_csv $'0.1,0,0,0.1,0,256,0,0\n' 'field 5 (tex_w) = 0 is out of range; accepted 1 to 4096'
bad_csv $'0.1,0,0,0.1,256,-2,0,0\n' 'field 6 (tex_h) = -2'
bad_csv $'0.1,0,0,0.1,256,256,3841,0\n' 'field 7 (off_x) = 3841'
bad_csv $'h1,h2,h3,h4,h5,h6,h7,h8\nh1,h2,h3,h4,h5,h6,h7,h8\n' 'line 2: field 1 (dudx)'
# A first row whose numbers underflow a float is data, not a header: one query in, one out.
printf '1e-45,0,0,1e-45,256,256,0,0\n' >"$tmp/tiny.csv"
ok lod --levels 13 "$tmp/tiny.csv" "$tmp/tiny_out.csv"
[[ "$(wc -l <"$tmp/tiny_out.csv")" == 1 && "$(cut -d, -f1 "$tmp/tiny_out.csv")" == 1e-45 ]] ||
  fail "lod dropped or changed the underflowing first row: $(cat "$tmp/tiny_out.csv")"
# Endless and huge inputs stop at the caps at once (exit 2, the cap named), not after gigabytes.
start=$(date +%s)
timeout 60 "$GLINT" lod --levels 13 /dev/zero "$tmp/x.csv" >"$tmp/out" 2>"$tmp/err"
rc=$?
((rc == 2)) && grep -q 'line 1: longer than 1024 bytes' "$tmp/err" || fail "lod /dev/zero -> exit $rc: $(cat "$tmp/err")"
(($(date +%s) - start < 30)) || fail "lod /dev/zero took $(($(date +%s) - start)) s"
truncate -s 50G "$tmp/sparse.csv" 2>/dev/null && {
  bad lod --levels 13 "$tmp/sparse.csv" "$tmp/x.csv"
  grep -q 'longer than 1024 bytes' "$tmp/err" || fail "lod on a sparse 50 GB file: $(cat "$tmp/err")"
  rm -f "$tmp/sparse.csv"
}
# --aniso 0 is isotropic, as --help says: the same levels as no --aniso at all.
ok lod --levels 13 --aniso 0 "$tmp/q.csv" "$tmp/lod_iso.csv"
cmp -s "$tmp/lod.csv" "$tmp/lod_iso.csv" || fail "lod --aniso 0 differs from isotropic"

# glint flare: the demo's scene, depth and light list replayed. The statistics must be the demo's,
# with one entry per light in input order, for every preset and both drawing paths.
# check_stats FILE TOTAL FRUSTUM OCCLUDED VISIBLE OVERFLOW DISABLED
check_stats() {
  python3 - "$@" <<'PY' || fail "stats $1 do not match: $(head -c 300 "$1")"
import json, sys
path, total, frustum, occluded, visible, overflow, disabled = sys.argv[1], *map(int, sys.argv[2:])
s = json.load(open(path))
assert (s["total"], s["frustum_culled"], s["occluded"], s["visible"], s["overflow"], s["disabled"]) == \
    (total, frustum, occluded, visible, overflow, disabled), s
lights = s["lights"]
assert len(lights) == total
names = [l["culled"] for l in lights]
assert names.count("frustum") == frustum and names.count("occluded") == occluded
assert names.count("disabled") == disabled and names.count("overflow") == overflow
assert names.count(None) == visible - overflow
for l in lights:
    f = l["visible_fraction"]
    assert (0 < f <= 1) if l["culled"] is None else f == 0, l
PY
}
d="$tmp/demo"
flare_args=(--color "$d/scene.exr" --depth "$d/depth.exr" --lights "$d/lights.json")
for preset in retro_subtle RETRO_INTENSE Cinematic disabled; do
  for draw in raster compute; do
    ok flare "${flare_args[@]}" "$tmp/f_${preset}_$draw.exr" --preset "$preset" --draw "$draw" \
      --stats "$tmp/s_${preset}_$draw.json"
    expect_file "$tmp/f_${preset}_$draw.exr"
    check_stats "$tmp/s_${preset}_$draw.json" 14 2 3 8 0 1
  done
done
# The light list's order is kept: the demo's lights 7-9 are the ones behind the occluders.
python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert [l["culled"] for l in s["lights"]][6:9] == ["occluded"] * 3, s["lights"]
' "$tmp/s_Cinematic_raster.json" || fail "glint flare stats are not in input order"
ok flare "${flare_args[@]}" "$tmp/f_grid.exr" --grid 16 --fp32
ok flare "${flare_args[@]}" "$tmp/f_grid1.exr" --grid 1 --stats "$tmp/s_grid1.json"
check_stats "$tmp/s_grid1.json" 14 2 3 8 0 1
# --reverse-z on the demo's standard depth: the far plane (1) now counts as near, so the sky lights
# become occluded; the frustum and disabled verdicts do not depend on the depth.
ok flare "${flare_args[@]}" "$tmp/f_rev.exr" --reverse-z --stats "$tmp/s_rev.json"
python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["total"] == 14 and s["frustum_culled"] == 2 and s["disabled"] == 1 and s["occluded"] > 3, s
' "$tmp/s_rev.json" || fail "glint flare --reverse-z stats: $(head -c 200 "$tmp/s_rev.json")"
python3 - "$d/lights.json" "$tmp/empty_lights.json" "$tmp/many.json" "$tmp/70k.json" <<'PY'
import json, sys
src = json.load(open(sys.argv[1]))
json.dump({"view_proj": src["view_proj"], "lights": []}, open(sys.argv[2], "w"))
# 2000 copies of the demo's first (visible) light: more than the compute path's capacity on some
# devices is fine, overflow is reported per light.
json.dump({"view_proj": src["view_proj"], "lights": [src["lights"][0]] * 2000}, open(sys.argv[3], "w"))
# 70000 lights: more instances than one row of dispatch workgroups holds on some devices (65535).
json.dump({"view_proj": src["view_proj"], "lights": [src["lights"][0]] * 70000}, open(sys.argv[4], "w"))
PY
ok flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/empty_lights.json" "$tmp/f_none.exr" \
  --stats "$tmp/s_none.json"
check_stats "$tmp/s_none.json" 0 0 0 0 0 0
ok flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/many.json" "$tmp/f_many.exr" --draw compute \
  --stats "$tmp/s_many.json"
python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["total"] == 2000 and s["visible"] == 2000 and len(s["lights"]) == 2000, s["total"]
assert sum(l["culled"] is None for l in s["lights"]) + s["overflow"] == 2000
' "$tmp/s_many.json" || fail "glint flare with 2000 lights on one spot"
ok flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/70k.json" "$tmp/f_70k.exr" --stats "$tmp/s_70k.json"
python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["total"] == 70000 and s["visible"] == 70000 and s["overflow"] == 0, {k: s[k] for k in s if k != "lights"}
' "$tmp/s_70k.json" || fail "glint flare with 70000 lights"

# glint flare: bad command lines, files and light lists (exit 2, one line).
bad flare "${flare_args[@]}"
bad flare --depth "$d/depth.exr" --lights "$d/lights.json" "$tmp/x.exr"
bad flare "${flare_args[@]}" "$tmp/x.exr" --preset sparkly
bad flare "${flare_args[@]}" "$tmp/x.exr" --grid 0
bad flare "${flare_args[@]}" "$tmp/x.exr" --grid 17
bad flare "${flare_args[@]}" "$tmp/x.exr" --grid -1
bad flare "${flare_args[@]}" "$tmp/x.exr" --draw splat
bad flare "${flare_args[@]}" "$tmp/x.exr" --no-such-flag
bad flare "${flare_args[@]}" "$tmp/x.exr" --stats "$tmp/no/such/dir/s.json"
bad flare "${flare_args[@]}" "$tmp/no/such/dir/x.exr"
bad flare "${flare_args[@]}" "$tmp/x.exr" --stats "$tmp/x.exr"
bad flare "${flare_args[@]}" "$tmp/x.exr" --device no-such-gpu
bad flare --color "$tmp/missing.exr" --depth "$d/depth.exr" --lights "$d/lights.json" "$tmp/x.exr"
bad flare --color "$d/scene.exr" --depth "$tmp/missing.exr" --lights "$d/lights.json" "$tmp/x.exr"
bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/missing.json" "$tmp/x.exr"
bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp" "$tmp/x.exr"
bad flare --color "$d/scene.exr" --depth "$tmp/noise.exr" --lights "$d/lights.json" "$tmp/x.exr"
bad flare --color "$d/scene.exr" --depth "$tmp/tiny/depth.exr" --lights "$d/lights.json" "$tmp/x.exr"  # 1x1
grep -q 'sizes must match' "$tmp/err" || fail "size mismatch message: $(cat "$tmp/err")"
# Bad JSON of each kind: the message names the JSON path.
bad_json() {  # bad_json 'TEXT' 'EXPECTED PART OF THE MESSAGE'
  printf '%s' "$1" >"$tmp/bad.json"
  bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/bad.json" "$tmp/x.exr"
  grep -qF -- "$2" "$tmp/err" || fail "bad JSON '$1': message lacks '$2': $(cat "$tmp/err")"
}
vp='[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]'
bad_json '' 'invalid JSON'
bad_json '{"view_proj": '"$vp"', "lights": [' 'invalid JSON'
bad_json '[]' 'expected an object'
bad_json '{"lights": []}' 'view_proj: missing'
bad_json '{"view_proj": '"$vp"'}' 'lights: missing'
bad_json '{"view_proj": [1,2,3], "lights": []}' 'view_proj: has 3 numbers'
bad_json '{"view_proj": '"$vp"', "lights": [{"color": [1,1,1]}]}' 'lights[0]: "position" is missing'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0]}]}' 'lights[0].position: has 2 numbers'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,"1"]}]}' 'lights[0].position[2]: expected'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,0], "intensity": -1}]}' 'lights[0].intensity: -1'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,0], "size": -2}]}' 'lights[0].size: -2'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,0], "size": 1e6}]}' 'at most 4096'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,0], "element": "sparkle"}]}' 'unknown element'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,1e39,0]}]}' 'float range'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,1e999,0]}]}' 'overflow'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,NaN,0]}]}' 'invalid JSON'
bad_json '{"view_proj": '"$vp"', "lights": [], "extra": 1}' 'unknown key'
bad_json '{"view_proj": '"$vp"', "lights": [{"position": [0,0,0], "size": 1, "size": 2}]}' 'duplicate key'
python3 -c 'print("[" * 200000)' >"$tmp/deep.json"
bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/deep.json" "$tmp/x.exr"
python3 -c 'print("{\"lights\": [" + "[" * 200000)' >"$tmp/deep2.json"
bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/deep2.json" "$tmp/x.exr"
head -c 4096 /dev/urandom >"$tmp/noise.json"
bad flare --color "$d/scene.exr" --depth "$d/depth.exr" --lights "$tmp/noise.json" "$tmp/x.exr"

# glint cull: spheres and boxes against the demo's depth image; the state list and counts, and bad
# object files (exit 2 naming the object and field, no output left behind).
proj='[1,0,0,0, 0,1,0,0, 0,0,-1.001001,-1, 0,0,-0.1001001,0]'
ident='[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]'
printf '%s' '{"view": '"$ident"', "proj": '"$proj"', "objects": [
  {"sphere": [0, 0, -5, 0.5]}, {"sphere": [0, 0, 5, 1]}, {"box": [-1, -1, -3, 1, 1, -2]},
  {"sphere": [0, 0, -0.1, 0.5]}, {"box": [100, 0, -3, 101, 1, -2]}]}' >"$tmp/objects.json"
ok cull --depth "$d/depth.exr" --objects "$tmp/objects.json" "$tmp/cull.json" --stats
expect_file "$tmp/cull.json"
grep -q '^objects: 5 total' "$tmp/out" || fail "glint cull printed no statistics"
python3 - "$tmp/cull.json" <<'PY' || fail "glint cull output: $(head -c 300 "$tmp/cull.json")"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["total"] == 5 and len(r["objects"]) == 5
assert r["objects"][1] == "frustum" and r["objects"][4] == "frustum"  # behind the camera; far to the side
assert r["objects"][3] == "visible"  # crosses the near plane
assert r["frustum_culled"] + r["occluded"] + r["visible"] == 5
assert r["frustum_culled"] == r["objects"].count("frustum") and r["visible"] == r["objects"].count("visible")
PY
rproj='[1,0,0,0, 0,1,0,0, 0,0,0.001001,-1, 0,0,0.1001001,0]'
printf '%s' '{"view": '"$ident"', "proj": '"$rproj"', "objects": [{"sphere": [0, 0, -5, 0.5]}]}' >"$tmp/robjects.json"
ok cull --depth "$d/depth.exr" --objects "$tmp/robjects.json" "$tmp/rcull.json" --reverse-z
bad cull --depth "$d/depth.exr" --objects "$tmp/robjects.json" "$tmp/x.json"  # reversed projection, standard depth
bad_cull() {  # bad_cull JSON NEEDLE
  printf '%s' "$1" >"$tmp/bad_objects.json"
  rm -f "$tmp/bad_out.json"
  bad cull --depth "$d/depth.exr" --objects "$tmp/bad_objects.json" "$tmp/bad_out.json"
  grep -q -- "$2" "$tmp/err" || fail "glint cull error for $1 does not name '$2': $(cat "$tmp/err")"
  if [[ -e "$tmp/bad_out.json" || -n "$(find "$tmp" -maxdepth 1 -name "*.glint-tmp")" ]]; then fail "glint cull left an output after an error"; fi
}
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"sphere": [0,0,-5,1]}, {"sphere": [0,0,-5,-1]}]}' 'objects\[1\].sphere\[3\]'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"box": [0,0,0,1,1]}]}' 'objects\[0\].box'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"box": [2,0,0,1,1,1]}]}' 'objects\[0\].box\[0\]'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"sphere": [0,"x",0,1]}]}' 'objects\[0\].sphere\[1\]'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"sphere": [0,1e39,0,1]}]}' 'objects\[0\].sphere\[1\]'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [{"cone": [0,0,0,1]}]}' 'objects\[0\]'
bad_cull '{"view": '"$ident"', "proj": '"$proj"', "objects": [], "extra": 1}' 'unknown key'
bad_cull '{"view": [1,2,3], "proj": '"$proj"', "objects": []}' 'view'
bad_cull '{"view": '"$ident"', "proj": [1,0,0,0, 0,1,0,0, 0,0,-1,-1, 0,0,-0.1,1], "objects": []}' 'proj\[15\]'
bad_cull '[1' 'not JSON'
bad cull --depth "$tmp/missing.exr" --objects "$tmp/objects.json" "$tmp/x.json"
bad cull --depth "$d/depth.exr" --objects "$tmp/missing.json" "$tmp/x.json"
bad cull --depth "$d/depth.exr" --objects "$tmp/objects.json" "$tmp/no/such/dir/x.json"

# Outputs are replaced atomically: a failing write (a file-size limit, as a full disk) and SIGTERM
# while writing both leave the previous files intact and no temporaries.
no_temporaries() {  # no_temporaries DIR WHAT
  local left
  left="$(find "$1" -name '*.glint-tmp')"
  [[ -z "$left" ]] || fail "$2 left temporaries: $left"
}
ok bloom "$scene" "$tmp/atomic.exr" --png "$tmp/atomic.png"
cp "$tmp/atomic.exr" "$tmp/atomic.exr.before"
cp "$tmp/atomic.png" "$tmp/atomic.png.before"
# 8 KiB: less than the EXR; the PNG is not written. SIGXFSZ is ignored, so the write fails cleanly.
(ulimit -f 8 && "$GLINT" bloom "$scene" "$tmp/atomic.exr" --png "$tmp/atomic.png" --intensity 2 >"$tmp/out" 2>"$tmp/err")
rc=$?
((rc == 2)) && grep -q '^glint: error: .*atomic.exr: .*File too large' "$tmp/err" ||
  fail "bloom under ulimit -f 8 -> exit $rc: $(cat "$tmp/err")"
cmp -s "$tmp/atomic.exr" "$tmp/atomic.exr.before" || fail "a failed bloom write changed the previous EXR"
cmp -s "$tmp/atomic.png" "$tmp/atomic.png.before" || fail "a failed bloom write changed the previous PNG"
no_temporaries "$tmp" "a failed bloom write"
# The demo's six files: the first three (scene.exr, depth.exr, lights.json) fit under the limit,
# flares.exr (the scene plus flares) does not; none of the six is replaced.
ok demo --size 96x64 --variant 7 --out "$tmp/atomic_demo"
(cd "$tmp/atomic_demo" && md5sum * >"$tmp/atomic_demo.md5")
ok demo --size 128x128 --out "$tmp/atomic_sizes"
first=$(stat -c %s "$tmp/atomic_sizes/scene.exr" "$tmp/atomic_sizes/depth.exr" "$tmp/atomic_sizes/lights.json" | sort -n | tail -1)
limit=$((first / 1024 + 1))
if (($(stat -c %s "$tmp/atomic_sizes/flares.exr") > limit * 1024)); then
  (ulimit -f "$limit" && "$GLINT" demo --size 128x128 --out "$tmp/atomic_demo" >"$tmp/out" 2>"$tmp/err")
  rc=$?
  ((rc == 2)) && grep -q 'flares.exr: .*File too large' "$tmp/err" ||
    fail "demo under ulimit -f $limit -> exit $rc: $(cat "$tmp/err")"
else
  echo "cli_test: note: flares.exr is no larger than scene.exr on this device; partial-write case skipped"
fi
(cd "$tmp/atomic_demo" && md5sum -c --quiet "$tmp/atomic_demo.md5") || fail "a failed demo write changed earlier files"
no_temporaries "$tmp/atomic_demo" "a failed demo write"
# SIGTERM as soon as the first temporary appears (the demo writes six 1024x1024 files after it).
"$GLINT" demo --size 1024x1024 --out "$tmp/atomic_demo" >"$tmp/out" 2>"$tmp/err" &
pid=$!
seen=0
for ((i = 0; i < 12000; ++i)); do  # up to 120 s at 10 ms (a cold shader cache on a busy machine)
  if [[ -n "$(find "$tmp/atomic_demo" -name '*.glint-tmp' 2>/dev/null)" ]]; then
    kill -TERM "$pid"
    seen=1
    break
  fi
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.01
done
wait "$pid"
rc=$?
((seen)) || fail "never saw the demo's temporaries (exit $rc)"
((rc == 143)) || fail "demo killed by SIGTERM -> exit $rc (expected 143): $(cat "$tmp/err")"
(cd "$tmp/atomic_demo" && md5sum -c --quiet "$tmp/atomic_demo.md5") || fail "SIGTERM during the demo's write changed earlier files"
no_temporaries "$tmp/atomic_demo" "SIGTERM during the demo's write"

if ((failures)); then
  printf 'cli_test: %d failure(s)\n' "$failures" >&2
  exit 1
fi
echo "cli_test: ok"
