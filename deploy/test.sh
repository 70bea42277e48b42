#!/usr/bin/env bash
# Installs what is missing, builds (Release, warnings as errors) and runs every test through CTest.
# Exits non-zero on any failure. BUILD_DIR and JOBS may be overridden.
#
# Once per CI run (CI=true), or on request, two more stages (issue #10):
#   GIS_SANITIZE_TESTS=1  unit and stability tests under AddressSanitizer + UBSan, leak checks on
#                         (preset asan-ci, build/asan-ci). GIS_SANITIZE_SCOPE=core (default) takes the
#                         core, scene and render unit tests and the stability suite, which fits the
#                         12-minute budget of this stage on 2 cores; =all adds every other layer's
#                         unit tests (about twice the build: docs/stability.md)
#   GIS_FUZZ_TESTS=1      the libFuzzer targets (clang, build/fuzz), each for FUZZ_SECONDS (default
#                         40: three targets, two minutes in all) on a copy of its committed seed
#                         corpus in tests/fuzz/corpus/
# Set either to 0 to skip it in CI.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build/ci}"
JOBS="${JOBS:-$(nproc)}"
default_extra=0
[[ "${CI:-}" == "true" ]] && default_extra=1
SANITIZE="${GIS_SANITIZE_TESTS:-$default_extra}"
FUZZ="${GIS_FUZZ_TESTS:-$default_extra}"
FUZZ_SECONDS="${FUZZ_SECONDS:-40}"

bash "$ROOT/deploy/install-deps.sh"

cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGIS_WERROR=ON >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"

# Tests that render share the 2 cores with llvmpipe's own threads: run them two at a time.
(cd "$BUILD_DIR" && ctest --output-on-failure -j 2 --timeout 600 "$@")

if [[ "$SANITIZE" == 1 ]]; then
    echo "== unit and stability tests under ASan + UBSan (build/asan-ci)"
    (cd "$ROOT" && cmake --preset asan-ci >/dev/null)
    # Only the test executables the labels need (the GL test binary runs under label gl only).
    if [[ "${GIS_SANITIZE_SCOPE:-core}" == all ]]; then
        mapfile -t targets < <(ninja -C "$ROOT/build/asan-ci" -t targets all | grep -oE '^gis_[a-z_]+_tests' |
                               grep -vx gis_gl_tests | sort -u)
    else
        targets=(gis_core_tests gis_scene_tests gis_frame_tests gis_job_tests gis_stability_tests)
    fi
    cmake --build "$ROOT/build/asan-ci" -j "$JOBS" --target "${targets[@]}"
    # Unbuilt test executables only add an unlabelled *_NOT_BUILT placeholder, which -L leaves out.
    # No LSan suppressions are needed: the GL tests destroy their contexts, and Mesa frees with them.
    (cd "$ROOT" && ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
        UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
        ctest --preset asan-ci -L "unit|stability" -j 2 --timeout 900)
fi

if [[ "$FUZZ" == 1 ]]; then
    echo "== libFuzzer targets, ${FUZZ_SECONDS} s each (build/fuzz)"
    # deploy/install-deps.sh does not install clang: say so instead of failing inside CMake.
    command -v clang++ >/dev/null || { echo "the fuzz stage needs clang with libFuzzer (apt-get install clang)"; exit 1; }
    flags="-fsanitize=fuzzer-no-link,address,undefined"
    CC=clang CXX=clang++ cmake -S "$ROOT" -B "$ROOT/build/fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DGIS_FUZZ=ON -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" >/dev/null
    cmake --build "$ROOT/build/fuzz" -j "$JOBS" --target gis_fuzz_gltf gis_fuzz_archive gis_fuzz_protocol
    for target in gltf archive protocol; do
        # A scratch copy: new corpus entries stay out of the tree; crashes land in build/fuzz.
        work="$(mktemp -d)"
        cp -r "$ROOT/tests/fuzz/corpus/$target/." "$work/"
        "$ROOT/build/fuzz/tests/fuzz/gis_fuzz_$target" -max_total_time="$FUZZ_SECONDS" -timeout=10 \
            -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$ROOT/build/fuzz/$target-" "$work" \
            >"$ROOT/build/fuzz/$target.log" 2>&1 || { tail -n 60 "$ROOT/build/fuzz/$target.log"; exit 1; }
        echo "gis_fuzz_$target: $(grep -m1 'stat::number_of_executed_units' "$ROOT/build/fuzz/$target.log")"
        rm -rf "$work"
    done
fi
