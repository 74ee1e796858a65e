#!/usr/bin/env bash
# egress set-up, build and run. On a fresh Debian bookworm machine, as root:
#   ./egress.sh demo    install missing packages, build (Release), run the main job
#   ./egress.sh test    install missing packages, build (Release), run the whole test suite
# Other sub-commands:
#   ./egress.sh deps       install the missing Debian packages only (deps/apt-packages.txt)
#   ./egress.sh build      configure and build only
#   ./egress.sh sanitize   build with AddressSanitizer + UBSan in build-asan/ and run the tests
#   ./egress.sh bench      build and run the Google Benchmark programs in bench/
#   ./egress.sh deps-slurm install Slurm and munge (deps/apt-packages-slurm.txt) for deploy/slurm
#                          and its test, which is skipped without them
#   ./egress.sh fuzz [S]   build the libFuzzer targets (clang, ASan + UBSan) in build-fuzz/ and
#                          run each for S seconds (default 60) from seeds of the project's files
# Environment: EGRESS_BUILD_DIR (default build), EGRESS_ASAN_BUILD_DIR (default build-asan),
# EGRESS_FUZZ_BUILD_DIR (default build-fuzz), EGRESS_JOBS (default: all cores),
# EGRESS_REFERENCE_DIR (shared reference data; default ../shared/reference).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cd "$root"
jobs=${EGRESS_JOBS:-$(nproc)}

# ccache (CMake uses it when it is installed): paths inside the checkout are hashed relative to
# it and the build folder is not hashed, so a clone in another folder (CI's clean clone) builds
# from the objects this checkout's builds left; the cache holds all three configurations
# (Release, sanitizers, fuzz). A cold build of one takes ~40 min on 2 cores.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}
export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-true}
export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-20G}

say() { printf '\033[1m[egress]\033[0m %s\n' "$*"; }
die() { printf '[egress] error: %s\n' "$*" >&2; exit 1; }

# Installs the packages of deps/apt-packages.txt that are not installed yet. Silent when
# everything is present; apt-get update runs only when something must be installed.
install_deps() {
  local wanted missing=() list=${1:-deps/apt-packages.txt}
  wanted=$(sed -e 's/#.*//' -e '/^[[:space:]]*$/d' "$list")
  for pkg in $wanted; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then
      missing+=("$pkg")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  say "installing ${#missing[@]} missing Debian package(s): ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || die "packages missing (${missing[*]}); run as root or install sudo"
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# configure_and_build <build-dir> [extra cmake args...]
configure_and_build() {
  local dir=$1; shift
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    say "configuring $dir"
    mkdir -p "$dir"
    cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DEGRESS_WERROR=ON "$@" \
      >"$dir/configure.log" 2>&1 || { cat "$dir/configure.log"; die "configure failed"; }
  fi
  say "building $dir ($jobs jobs)"
  cmake --build "$dir" -j "$jobs"
}

run_tests() {
  local dir=$1
  say "running the tests in $dir"
  ctest --test-dir "$dir" --output-on-failure -j "$jobs"
}

build_dir=${EGRESS_BUILD_DIR:-build}
asan_dir=${EGRESS_ASAN_BUILD_DIR:-build-asan}
command=${1:-help}
case "$command" in
  deps)
    install_deps
    ;;
  build)
    install_deps
    configure_and_build "$build_dir"
    ;;
  demo)
    install_deps
    configure_and_build "$build_dir"
    say "the main job: egress --version (the libraries each module links)"
    "$build_dir/apps/egress" --version
    echo
    say "a twin scenario end to end, driven by the robot brain: S5, through the office's two doors"
    say "(push button, then glass door with a proximity plate) to fetch a water bottle from the far"
    say "room, back through both and onto the start room's table"
    "$build_dir/apps/egress" sim run worlds/scenarios/s5_office_chain.yaml \
      --png "$build_dir/demo_run.png" --video "$build_dir/demo_run.mp4" \
      --trace "$build_dir/demo_run.jsonl" --overwrite
    echo
    say "a base path across the office SDF world through door_a and door_b, drawn to $build_dir/demo_path.png"
    "$build_dir/apps/egress" plan --local --map worlds/office/office.sdf --start 1.5 4.5 0 --goal 12.5 1.5 0 \
      --png "$build_dir/demo_path.png" --overwrite
    echo
    say "the same with door_a closed: no path, and the planner says why"
    "$build_dir/apps/egress" plan --local --map worlds/office/office.sdf --start 1.5 4.5 0 --goal 12.5 1.5 0 \
      --closed door_a || true
    ;;
  test)
    install_deps
    configure_and_build "$build_dir"
    run_tests "$build_dir"
    ;;
  sanitize)
    install_deps
    configure_and_build "$asan_dir" -DEGRESS_SANITIZE=ON \
      -DEGRESS_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
      run_tests "$asan_dir"
    ;;
  bench)
    install_deps
    configure_and_build "$build_dir"
    for program in "$build_dir"/bench/*_bench; do
      say "$program"
      "$program"
    done
    ;;
  deps-slurm)
    install_deps deps/apt-packages-slurm.txt
    ;;
  fuzz)
    seconds=${2:-60}
    [[ "$seconds" =~ ^[0-9]+$ ]] && [ "$seconds" -gt 0 ] || die "fuzz: SECONDS must be a positive integer"
    install_deps
    install_deps deps/apt-packages-fuzz.txt
    fuzz_dir=${EGRESS_FUZZ_BUILD_DIR:-build-fuzz}
    if [ ! -f "$fuzz_dir/CMakeCache.txt" ]; then
      say "configuring $fuzz_dir (clang, libFuzzer, ASan + UBSan)"
      mkdir -p "$fuzz_dir"
      generator=()
      command -v ninja >/dev/null && generator=(-G Ninja)
      CC=clang CXX=clang++ cmake -S . -B "$fuzz_dir" "${generator[@]}" -DEGRESS_FUZZ=ON \
        -DEGRESS_BUILD_TESTS=OFF -DEGRESS_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        >"$fuzz_dir/configure.log" 2>&1 || { cat "$fuzz_dir/configure.log"; die "configure failed"; }
    fi
    say "building the fuzz targets in $fuzz_dir ($jobs jobs)"
    cmake --build "$fuzz_dir" -j "$jobs" --target egress_fuzz
    fuzz/run_fuzzers.sh "$fuzz_dir" "$seconds"
    ;;
  help|-h|--help)
    sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'
    ;;
  *)
    die "unknown sub-command '$command' (try: demo, test, deps, deps-slurm, build, sanitize, bench, fuzz)"
    ;;
esac
