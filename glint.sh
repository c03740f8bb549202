#!/usr/bin/env bash
# One entry point on a fresh Debian 12 machine (run as root; no GPU needed: lavapipe runs Vulkan on
# the CPU).
#   ./glint.sh demo [args]   install what is missing, build, run `glint demo [args]`
#   ./glint.sh test [args]   install, build, run ctest [args] on lavapipe with validation, a CLI
#                            smoke test, then install into a temporary prefix and build and run
#                            tests/consumer against it through find_package(glint)
#   ./glint.sh bench [args]  install, build, run build/bench/glint_bench [args]
# Environment:
#   GLINT_BUILD_DIR   build directory (default: build)
#   GLINT_DEVICE      device for the CLI and tests (index or name part); when set, or when
#                     VK_DRIVER_FILES / VK_ICD_FILENAMES is set, `test` does not force lavapipe
#   GLINT_VALIDATION  `test` exports 1 unless it is already set
set -euo pipefail
cd "$(dirname "$0")"

BUILD_DIR="${GLINT_BUILD_DIR:-build}"
LAVAPIPE_ICD="/usr/share/vulkan/icd.d/lvp_icd.$(uname -m).json"
# make: CMake's default generator needs it and only cmake's Recommends pull it in.
PACKAGES=(mesa-vulkan-drivers libvulkan-dev glslang-tools spirv-tools vulkan-validationlayers libglm-dev
          libopenexr-dev libgtest-dev libbenchmark-dev cmake make g++ libpng-dev nlohmann-json3-dev
          libcli11-dev python3)

log() { printf 'glint.sh: %s\n' "$*" >&2; }
die() { log "error: $*"; exit 1; }

usage() {  # prints the comment block at the top of this file
  sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0" >&2
  exit "$1"
}

install_packages() {
  local missing=() p
  for p in "${PACKAGES[@]}"; do
    # dpkg -s also answers for removed packages whose config files remain; check the status line.
    dpkg -s "$p" 2>/dev/null | grep -q '^Status: install ok installed' || missing+=("$p")
  done
  ((${#missing[@]} == 0)) && return 0
  local sudo=()
  if ((EUID != 0)); then
    command -v sudo >/dev/null || die "missing packages (${missing[*]}); run as root to install them"
    sudo=(sudo)
  fi
  log "installing ${missing[*]}"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

# configure OPTION...: configures once; re-runs CMake only to switch on a needed GLINT_BUILD_* option
# that an earlier configure left off (e.g. a build dir made with -DGLINT_BUILD_TESTS=OFF).
configure() {
  local cache="$BUILD_DIR/CMakeCache.txt" opt flags=()
  for opt in "$@"; do flags+=("-D$opt=ON"); done
  if [[ ! -f "$cache" ]]; then
    cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${flags[@]}"
    return
  fi
  for opt in "$@"; do
    if ! grep -q "^$opt:BOOL=ON$" "$cache"; then
      cmake -S . -B "$BUILD_DIR" "${flags[@]}"
      return
    fi
  done
}

build() { cmake --build "$BUILD_DIR" -j"$(nproc)" "$@"; }

use_lavapipe_unless_told_otherwise() {
  if [[ -n "${GLINT_DEVICE:-}${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]]; then
    log "device chosen by GLINT_DEVICE / VK_DRIVER_FILES / VK_ICD_FILENAMES"
  elif [[ -f "$LAVAPIPE_ICD" ]]; then
    export VK_DRIVER_FILES="$LAVAPIPE_ICD" VK_ICD_FILENAMES="$LAVAPIPE_ICD"
    log "tests run on lavapipe ($LAVAPIPE_ICD); set GLINT_DEVICE or VK_DRIVER_FILES for another device"
  else
    log "warning: $LAVAPIPE_ICD not found; the Vulkan loader picks the drivers"
  fi
}

consumer_check() {
  local tmp
  tmp="$(mktemp -d)"
  # shellcheck disable=SC2064  # expand $tmp now
  trap "rm -rf '$tmp'" EXIT
  log "installing into $tmp/prefix and building tests/consumer with find_package(glint)"
  cmake --install "$BUILD_DIR" --prefix "$tmp/prefix" >"$tmp/install.log" ||
    { cat "$tmp/install.log" >&2; die "cmake --install failed"; }
  cmake -S tests/consumer -B "$tmp/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log" >&2; die "configuring tests/consumer failed"; }
  cmake --build "$tmp/build" -j"$(nproc)" >"$tmp/build.log" 2>&1 ||
    { cat "$tmp/build.log" >&2; die "building tests/consumer failed"; }
  local out
  out="$("$tmp/build/glint_consumer")" || { printf '%s\n' "$out" >&2; die "glint_consumer failed"; }
  printf '%s\n' "$out"
  [[ "$(tail -n 1 <<<"$out")" == ok ]] || die "glint_consumer did not print ok"
}

cmd="${1:-}"
[[ $# -gt 0 ]] && shift
case "$cmd" in
  demo)
    install_packages
    configure GLINT_BUILD_CLI
    build --target glint_cli
    exec "$BUILD_DIR/host/glint" demo "$@"
    ;;
  test)
    install_packages
    configure GLINT_BUILD_TESTS GLINT_BUILD_CLI
    build
    export GLINT_VALIDATION="${GLINT_VALIDATION:-1}"
    use_lavapipe_unless_told_otherwise
    ctest --test-dir "$BUILD_DIR" --output-on-failure --no-tests=error "$@"
    log "CLI smoke test"
    tests/cli_test.sh "$BUILD_DIR/host/glint"
    consumer_check
    log "all tests passed"
    ;;
  bench)
    install_packages
    configure GLINT_BUILD_BENCH
    build
    [[ -x "$BUILD_DIR/bench/glint_bench" ]] || die "no benchmark program ($BUILD_DIR/bench/glint_bench) was built"
    exec "$BUILD_DIR/bench/glint_bench" "$@"
    ;;
  -h | --help | help) usage 0 ;;
  *)
    [[ -n "$cmd" ]] && log "unknown command '$cmd'"
    usage 2
    ;;
esac
