#!/usr/bin/env bash
# One entry point on a fresh Debian 12 machine (run as root; no GPU needed: lavapipe runs Vulkan on
# the CPU).
#   ./glint.sh demo [args]   install what is missing, build, run `glint demo [args]`
#   ./glint.sh test [args]   install, check the C++ layout (clang-format 14, see format_check), build
#                            the suite with ASan+UBSan (build-asan) and run ctest
#                            [args] on lavapipe with validation (leak checking for the CPU-only
#                            tests) and the CLI smoke test there; ctest's consumer_check installs into
#                            a temporary prefix, checks the library for getenv and tools' code
#                            (demo, references, io, CLI), and builds and runs
#                            tests/consumer against it through find_package(glint) and pkg-config;
#                            then each libFuzzer target for GLINT_FUZZ_SECONDS (default 10)
#   ./glint.sh fuzz [seconds] build the libFuzzer targets (clang, build-fuzz) and run each one for
#                            `seconds` (default 600) on a copy of fuzz/corpus/<name>; crashes are
#                            written to fuzz/findings/
#   ./glint.sh bench [args]  install, build, run build/bench/glint_bench [args]
# Environment:
#   GLINT_BUILD_DIR   build directory (default: build)
#   GLINT_DEVICE      device for the CLI and tests (index or name part); when set, or when
#                     VK_DRIVER_FILES / VK_ICD_FILENAMES is set, `test` does not force lavapipe
#   GLINT_VALIDATION  `test` exports 1 unless it is already set
#   GLINT_FUZZ_SECONDS  seconds per fuzz target in `test` (default 10; 0 skips the fuzz run)
#   GLINT_SKIP_ASAN   set to 1 to run the suite in the Release build instead (quick local runs)
set -euo pipefail
cd "$(dirname "$0")"

BUILD_DIR="${GLINT_BUILD_DIR:-build}"
LAVAPIPE_ICD="/usr/share/vulkan/icd.d/lvp_icd.$(uname -m).json"
# make: CMake's default generator needs it and only cmake's Recommends pull it in.
PACKAGES=(mesa-vulkan-drivers libvulkan-dev glslang-tools spirv-tools vulkan-validationlayers libglm-dev
          libopenexr-dev libgtest-dev libbenchmark-dev cmake make g++ libpng-dev nlohmann-json3-dev
          libcli11-dev python3 clang libclang-rt-14-dev clang-format)

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

# The ASan+UBSan build: the library, tests and CLI instrumented, the Vulkan loader, lavapipe and the
# validation layer not. Every memory access of glint's code is checked everywhere. Leaks: the
# CPU-only tests (label cpu) run with LeakSanitizer on; the GPU tests and the CLI run with it off,
# because the uninstrumented loader, driver and layer keep caches until exit that LSan reports,
# and the frames that name them are lost by the fast unwinder (the slow one makes the run take over
# ten minutes). glint's own leaks there are caught by the validation layer's object tracker and the
# memory bounds of tests/api_errors_test.cpp (ApiMemory.*), asserted in both builds: on RSS in
# Release, on the live heap of ASan's allocator here (RSS grows with ASan's quarantine by design).
asan_test() {
  local dir=build-asan
  # -O1 with line tables only (-g1): symbolized sanitizer reports at a fraction of the compile time
  # of -O3 and full debug information (this build is CI's critical path on 2 cores).
  [[ -f "$dir/CMakeCache.txt" ]] || cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DGLINT_SANITIZE=ON -DGLINT_BUILD_TESTS=ON -DGLINT_BUILD_BENCH=OFF -DGLINT_BUILD_CLI=ON -DGLINT_WERROR=ON
  cmake --build "$dir" -j"$(nproc)"
  local ubsan="print_stacktrace=1:halt_on_error=1"
  log "ASan+UBSan: CPU-only tests with leak checking"
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="$ubsan" \
    ctest --test-dir "$dir" --output-on-failure --no-tests=error -L cpu -j"$(nproc)"
  log "ASan+UBSan: GPU tests and the CLI smoke test"
  ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="$ubsan" \
    ctest --test-dir "$dir" --output-on-failure --no-tests=error -LE cpu -j"$(nproc)" "$@"
  ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="$ubsan" tests/cli_test.sh "$dir/tools/cli/glint"
  gpu_assisted_tests "$dir" "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1" "UBSAN_OPTIONS=$ubsan"
}

# GPU-assisted validation (instrumented shaders check buffer and descriptor accesses on the
# device) on the tests that compare every kernel with its reference (13 tests, 26 s in Release on
# 2 cores): the whole GPU suite under it would add minutes that CI's ten-minute budget does not
# have. CTest runs each test program as one entry, so the cases are picked by a gtest filter in
# every GPU program (a program without a matching case runs nothing).
GPU_AV_FILTER="*MatchesReference*:*MatchesItsReference*:*MatchesTheReference*:*MatchesTheFloat64*:*BatchKernelMatchesTheCppTwin*:*StatisticsAndResultsMatch*"
# GPU-assisted validation in the validation layer Debian 12 ships (1.3.239) does not follow
# descriptors pushed with vkCmdPushDescriptorSetKHR: its instrumented shaders take every pushed
# descriptor for uninitialized, report "Descriptor index 0 is uninitialized" and skip the access,
# so the kernels write nothing (reported upstream as KhronosGroup/Vulkan-ValidationLayers#5321).
# glint pushes every descriptor, so this step runs only with a layer of 1.3.250 or later (a
# release after that report was closed; check the layer's changelog before lowering it), and says
# so when it is skipped. Plain validation with synchronization validation checks every test.
GPU_AV_MIN_LAYER="1.3.250"
validation_layer_version() {
  local manifest
  for manifest in /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json \
                  /etc/vulkan/explicit_layer.d/VkLayer_khronos_validation.json; do
    [[ -f "$manifest" ]] && { sed -n 's/.*"api_version" *: *"\([0-9.]*\)".*/\1/p' "$manifest" | head -n1; return; }
  done
}
gpu_assisted_tests() {
  local dir="$1"; shift
  local have
  have="$(validation_layer_version)"
  if [[ -z "$have" || "$(printf '%s\n%s\n' "$GPU_AV_MIN_LAYER" "$have" | sort -V | head -n1)" != "$GPU_AV_MIN_LAYER" ]]; then
    log "GPU-assisted validation skipped: the validation layer is ${have:-not found}, GPU-AV follows pushed descriptors from $GPU_AV_MIN_LAYER on"
    return 0
  fi
  log "GPU-assisted validation: the reference comparisons"
  local programs=()
  mapfile -t programs < <(ctest --test-dir "$dir" -N -L gpu | sed -n 's/^ *Test *#[0-9]*: \([a-z0-9_]*_test\)$/\1/p')
  ((${#programs[@]} > 0)) || die "no GPU test programs found in $dir"
  # xargs replaces {} in arguments only, not in the command: env runs the program.
  printf '%s\n' "${programs[@]}" | xargs -P"$(nproc)" -I{} env "$@" GLINT_GPU_AV=1 "$dir/tests/{}" \
    --gtest_filter="$GPU_AV_FILTER" --gtest_brief=1 ||
    die "GPU-assisted validation failed (output above)"
}

# format_check: fails when clang-format 14 with the root .clang-format would change a C++ file.
# Checked: every tracked *.cpp and *.h except the shaders/ folders (src/<part>/shaders,
# tools/demo/shaders) and include/glint/gpu/, whose headers are also GLSL (shared structs with
# hand-aligned field comments and GLSL-only macros that clang-format reflows badly); those follow
# the layout by hand (CONTRIBUTING.md, "Layout"). Version 14 only:
# other versions lay some constructs out differently, so their verdict would not be CI's.
format_check() {
  command -v clang-format >/dev/null || die "clang-format is missing (apt-get install clang-format)"
  local version
  version="$(clang-format --version | grep -oE 'version [0-9]+' | grep -oE '[0-9]+')"
  [[ "$version" == 14 ]] || die "the format check needs clang-format 14 (Debian 12's); found ${version:-unknown}"
  local files=()
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    mapfile -t files < <(git ls-files '*.cpp' '*.h' ':!:*/shaders/*' ':!:include/glint/gpu/')
  else
    mapfile -t files < <(find bench fuzz include src tests tools \( -name '*.cpp' -o -name '*.h' \) |
      grep -v -e '^include/glint/gpu/' -e '/shaders/' | sort)
  fi
  log "format check: clang-format 14 over ${#files[@]} files"
  clang-format --dry-run -Werror "${files[@]}" ||
    die "clang-format would change the files above: run clang-format -i on them"
}

# run_fuzz SECONDS: builds fuzz/ with clang and runs each target on a scratch copy of its corpus.
run_fuzz() {
  local seconds="$1" dir=build-fuzz src name work
  [[ -f "$dir/CMakeCache.txt" ]] || cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DGLINT_BUILD_FUZZ=ON -DGLINT_BUILD_TESTS=OFF -DGLINT_BUILD_BENCH=OFF \
    -DGLINT_BUILD_CLI=OFF -DGLINT_WERROR=ON
  local targets=()
  for src in fuzz/fuzz_*.cpp; do targets+=(--target "$(basename "$src" .cpp)"); done
  cmake --build "$dir" -j"$(nproc)" "${targets[@]}"  # not the library: the targets need only tools/io
  mkdir -p fuzz/findings
  for src in fuzz/fuzz_*.cpp; do
    name="$(basename "$src" .cpp)"
    work="$(mktemp -d)"
    log "fuzzing $name for ${seconds}s (starting corpus fuzz/corpus/${name#fuzz_})"
    # OpenEXR may reserve (not touch) up to 2 GiB for an attribute's declared size before it finds
    # the file too short: allow that allocation, stop anything larger.
    "$dir/fuzz/$name" -max_total_time="$seconds" -malloc_limit_mb=2100 -rss_limit_mb=3072 -print_final_stats=1 \
      -artifact_prefix=fuzz/findings/ "$work" "fuzz/corpus/${name#fuzz_}" 2>"$work.log" ||
      { tail -n 60 "$work.log" >&2; rm -rf "$work" "$work.log"; die "$name found a failure (input in fuzz/findings/)"; }
    grep -E '^(Done|stat::number_of_executed_units)' "$work.log" >&2 || true
    rm -rf "$work" "$work.log"
  done
}

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

cmd="${1:-}"
[[ $# -gt 0 ]] && shift
case "$cmd" in
  demo)
    install_packages
    configure GLINT_BUILD_CLI
    build --target glint_cli
    exec "$BUILD_DIR/tools/cli/glint" demo "$@"
    ;;
  test)
    install_packages
    format_check
    export GLINT_VALIDATION="${GLINT_VALIDATION:-1}"
    use_lavapipe_unless_told_otherwise
    if [[ "${GLINT_SKIP_ASAN:-0}" == 1 ]]; then
      # Quick local runs: the suite in the Release build.
      configure GLINT_BUILD_TESTS GLINT_BUILD_CLI
      build
      ctest --test-dir "$BUILD_DIR" --output-on-failure --no-tests=error -j"$(nproc)" "$@"
      log "CLI smoke test"
      tests/cli_test.sh "$BUILD_DIR/tools/cli/glint"
      gpu_assisted_tests "$BUILD_DIR"
    else
      # Everything runs once, in the ASan+UBSan build (build-asan): the suite with validation
      # (consumer_check included: the example links the sanitized library, whose exported target
      # and glint.pc carry the sanitizer link flags) and the CLI smoke test. Building a second,
      # Release copy of the suite would double the CI's compile time on 2 cores; `demo` and
      # `bench` use the Release build.
      asan_test "$@"
    fi
    if [[ "${GLINT_FUZZ_SECONDS:-10}" != 0 ]]; then run_fuzz "${GLINT_FUZZ_SECONDS:-10}"; fi
    log "all tests passed"
    ;;
  fuzz)
    install_packages
    run_fuzz "${1:-600}"
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
