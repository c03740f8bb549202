#!/usr/bin/env bash
# The adoption check of an installed glint:
#   tests/consumer/check.sh BUILD_DIR [CXX]
# installs BUILD_DIR into a temporary prefix, then
#   1. checks that the installed libraries reference no getenv (the library reads no environment;
#      options go through ContextOptions), after proving the check finds the getenv of the tools'
#      library, which does read GLINT_* variables; and that they hold none of the tools' code
#      (demo scene and kernel, references, io, analysis, CLI), after proving that check on the
#      tools' libraries;
#   2. builds tests/consumer against the prefix with find_package(glint): the embedding example
#      and a compile of every installed header on its own (C++ and GLSL);
#   3. builds the example again with only `pkg-config --cflags --libs glint`;
#   4. runs both; each must print "ok" (validation on when GLINT_VALIDATION is set).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "${1:?usage: check.sh BUILD_DIR [CXX]}" && pwd)"
cxx="${2:-${CXX:-c++}}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
say() { printf 'consumer check: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 ||
  { cat "$tmp/install.log" >&2; die "cmake --install failed"; }
lib="$(find "$tmp/prefix" -name libglint.a -print -quit)"
[[ -n "$lib" ]] || die "no libglint.a installed"
libdir="$(dirname "$lib")"

# 1. No getenv in what an engine links. Any symbol named getenv / secure_getenv, defined or not.
getenv_symbols() { nm -A "$@" 2>/dev/null | awk '{ s = $NF; sub(/@.*/, "", s) } s ~ /^(__)?(secure_)?getenv$/'; }
tools="$(find "$build" -name libglint_tools.a -print -quit)"
if [[ -n "$tools" ]]; then
  [[ -n "$(getenv_symbols "$tools")" ]] || die "the getenv check finds nothing in $tools, which reads GLINT_*: the check is broken"
fi
found="$(getenv_symbols "$libdir"/libglint*.a)"
[[ -z "$found" ]] || { printf '%s\n' "$found" >&2; die "the installed library references getenv"; }
say "installed libraries reference no getenv"

# 1b. Nothing of the tools in what an engine links: no symbol (defined or referenced) of the demo
# scene and its starfield kernel, the float64 references, file io (EXR, PNG, JSON, CSV), the light
# statistics or the CLI, and no demo kernel id in the kernel table. The patterns are proven on the
# tools' libraries first, which hold each of them.
tool_symbols() {
  nm -A -C "$@" 2>/dev/null | grep -E 'glint::(demo|reference|io|analysis|cli|tools)::|[Ss]tarfield|Imf_[0-9_]*::|png_[a-z]|nlohmann::|lod_csv|lights_json'
  grep -l -a 'demo_starfield' "$@" 2>/dev/null | sed 's/$/: holds the string demo_starfield/'
}
tools_kernels="$(find "$build" -name libglint_tools_kernels.a -print -quit)"
if [[ -n "$tools" ]]; then
  in_tools="$(tool_symbols "$tools" || true)"
  for pattern in 'glint::demo::' 'glint::reference::' 'glint::io::' 'glint::analysis::' 'Imf_' 'png_' 'nlohmann::' \
                 'lod_csv' 'lights_json'; do
    grep -q -F -- "$pattern" <<<"$in_tools" ||
      die "the tools check finds no $pattern in $tools, which holds it: the check is broken"
  done
  [[ -n "$tools_kernels" ]] || die "no libglint_tools_kernels.a in $build"
  [[ "$(tool_symbols "$tools_kernels" | grep -c starfield || true)" -ge 2 ]] ||
    die "the tools check finds no starfield kernel in $tools_kernels: the check is broken"
fi
found="$(tool_symbols "$libdir"/libglint*.a)" || true
[[ -z "$found" ]] || { printf '%s\n' "$found" | head -n 40 >&2; die "the installed library holds tools' code (demo, references, io, CLI)"; }
say "installed libraries hold no demo, reference, io or CLI code"

# 2. find_package(glint): the example, and every installed header alone.
cmake -S "$here" -B "$tmp/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DCMAKE_CXX_COMPILER="$cxx" >"$tmp/configure.log" 2>&1 ||
  { cat "$tmp/configure.log" >&2; die "configuring tests/consumer failed"; }
cmake --build "$tmp/build" -j"$(nproc)" >"$tmp/build.log" 2>&1 ||
  { cat "$tmp/build.log" >&2; die "building tests/consumer (example and header checks) failed"; }
say "find_package build ok: $(find "$tmp/build/header_check" -name '*.cpp' | wc -l) C++ headers and $(find "$tmp/build/glsl_check" -name '*.comp' | wc -l) GLSL headers compile alone"

# 3. pkg-config.
pc="$(find "$tmp/prefix" -name glint.pc -print -quit)"
[[ -n "$pc" ]] || die "no glint.pc installed"
export PKG_CONFIG_PATH="$(dirname "$pc")${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
mkdir -p "$tmp/pc"
glslangValidator --quiet --target-env vulkan1.3 -I"$tmp/prefix/include" --vn engine_fill_spv \
  -o "$tmp/pc/engine_fill_spv.h" "$here/engine_fill.comp" || die "glslangValidator failed on engine_fill.comp"
# shellcheck disable=SC2046  # pkg-config prints several flags
"$cxx" -std=c++20 -O2 -Wall -Wextra -Werror -Wno-missing-field-initializers -I"$tmp/pc" "$here/main.cpp" \
  $(pkg-config --cflags glint) -o "$tmp/pc/glint_consumer" $(pkg-config --libs glint) ||
  die "building with pkg-config --cflags --libs glint failed"
say "pkg-config build ok ($(pkg-config --libs glint))"

# 4. Run both. Leak checking off: against a sanitized install, the Vulkan loader and driver keep
# allocations until exit that LeakSanitizer would report (glint's own leaks are caught by the suite).
for exe in "$tmp/build/glint_consumer" "$tmp/pc/glint_consumer"; do
  out="$(ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}" "$exe" 2>&1)" || { printf '%s\n' "$out" >&2; die "$exe failed"; }
  printf '%s\n' "$out"
  [[ "$(tail -n 1 <<<"$out")" == ok ]] || die "$exe did not print ok"
done
say "ok"
