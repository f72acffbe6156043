#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz/ with the stable toolchain and runs each for a
# bounded time. Called by `make fuzz-ci` (part of `make test`) and `make fuzz`.
#
#   tests/fuzz/run.sh SECONDS [TARGET...]     (default: every target)
#
# Stable Rust has no `-Zsanitizer=fuzzer`, but the coverage instrumentation libFuzzer needs is
# LLVM's SanitizerCoverage pass, which stable rustc runs with `-Cpasses=sancov-module` and the
# `-Cllvm-args` below (the flags cargo-fuzz passes); libFuzzer itself is compiled and linked by
# the libfuzzer-sys crate (pinned in tests/fuzz/Cargo.toml and Cargo.lock). `--target` keeps the
# flags off build scripts and proc macros. FUZZ_ASAN=1 adds AddressSanitizer, which is
# `-Zsanitizer=address` and so needs RUSTC_BOOTSTRAP=1 on stable (off by default: the targets
# are safe Rust apart from the C ABI's pointer handling, which the fuzzed buffers exercise at
# their exact lengths).
#
# Per target: the working corpus is target/fuzz/corpus/TARGET (grows across runs, not
# committed), seeded from tests/fuzz/corpus/TARGET (committed); crashing, timing-out or
# memory-hungry inputs are written to target/fuzz/artifacts/TARGET/ and the script exits 1
# (slow inputs are kept there too, as timeout-*, and listed; see the libFuzzer options below).
# Inputs that break only the soft contract (the core's *internal* error, Status::Internal or "a bug:
# please report the input": a clean error status, no non-finite number handed out, but a core
# defect; or a finite power fraction above 1) are kept in target/fuzz/findings/TARGET/ and
# listed; FUZZ_STRICT=1 (which `make test` sets) turns them into crashes: the run fails and the
# input is kept in target/fuzz/artifacts/TARGET/. FUZZ_EXHAUSTIVE=1 runs one process in which a
# timeout fails too, and skips nothing (see the libFuzzer options below).
# libFuzzer's seed is fixed (FUZZ_SEED, default 1) so that runs are repeatable up to timing.
# Prints the executions of each target and their total.
set -euo pipefail

secs=${1:?usage: run.sh SECONDS [TARGET...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(bridge calc_json calc_fields)
cargo=${CARGO:-$(command -v cargo || echo "$HOME/.cargo/bin/cargo")}
rustc=$(dirname "$cargo")/rustc
[ -x "$rustc" ] || rustc=rustc
triple=$("$rustc" -vV | sed -n 's/^host: //p')
out="$root/target/fuzz"

flags="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4"
flags+=" -Cllvm-args=-sanitizer-coverage-inline-8bit-counters"
flags+=" -Cllvm-args=-sanitizer-coverage-pc-table -Cllvm-args=-sanitizer-coverage-trace-compares"
flags+=" --cfg fuzzing -Cforce-frame-pointers=yes"
if [ "${FUZZ_ASAN:-0}" = 1 ]; then
  flags+=" -Zsanitizer=address"
  export RUSTC_BOOTSTRAP=1
fi
echo "building fuzz targets (${targets[*]}) into $out"
RUSTFLAGS="$flags" "$cargo" build --quiet --release --locked \
  --manifest-path "$here/Cargo.toml" --target "$triple" --target-dir "$out/build" \
  $(printf -- '--bin %s ' "${targets[@]}")

total=0
failed=()
for t in "${targets[@]}"; do
  bin="$out/build/$triple/release/$t"
  corpus="$out/corpus/$t"
  artifacts="$out/artifacts/$t/"
  mkdir -p "$corpus" "$artifacts"
  seeds=()
  [ -d "$here/corpus/$t" ] && seeds=("$here/corpus/$t")
  dict=()
  [ -f "$here/$t.dict" ] && dict=("-dict=$here/$t.dict")
  log="$out/$t.log"
  findings="$out/findings/$t"
  mkdir -p "$findings"
  rc=0
  # -rss_limit_mb: a memory blow-up is a crash; -max_len: documents and arguments are short.
  # Single inputs can be slow (an sRGB-integrated plate query near grazing incidence or with a
  # large index takes seconds to minutes: reported to the lead), so by default libFuzzer runs
  # in fork mode, where an input running longer than FUZZ_TIMEOUT (10 s) is kept as a
  # timeout-* artifact and listed, and fuzzing goes on; crashes and memory blow-ups stop the
  # run and fail (with FUZZ_STRICT=1 a soft finding is such a crash). FUZZ_EXHAUSTIVE=1: one
  # process, and a timeout (FUZZ_TIMEOUT, 60 s) fails too.
  if [ "${FUZZ_EXHAUSTIVE:-0}" = 1 ]; then
    mode=(-timeout="${FUZZ_TIMEOUT:-60}" -print_final_stats=1)
  else
    mode=(-fork=1 -ignore_timeouts=1 -ignore_ooms=0 -ignore_crashes=0 -timeout_exitcode=0
          -timeout="${FUZZ_TIMEOUT:-10}")
  fi
  FUZZ_FINDINGS="$findings" "$bin" -max_total_time="$secs" -seed="${FUZZ_SEED:-1}" "${mode[@]}" \
    -rss_limit_mb=2048 -max_len=4096 -artifact_prefix="$artifacts" ${dict[@]+"${dict[@]}"} \
    "$corpus" ${seeds[@]+"${seeds[@]}"} >"$log" 2>&1 || rc=$?
  # Executions: the final stats (one process) or the last status line "#N: cov: ..." (fork).
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  [ -n "$execs" ] || execs=$(grep -E '^#[0-9]+' "$log" | tail -1 | sed -n 's/^#\([0-9]*\).*/\1/p')
  cov=$(grep -oE 'cov: [0-9]+' "$log" | sed 's/cov: //' | sort -n | tail -1 || true)
  execs=${execs:-0}
  total=$((total + execs))
  if [ $rc -ne 0 ]; then
    failed+=("$t")
    echo "fuzz $t: FAILED (exit $rc) after $execs executions; input kept in $artifacts"
    grep -E 'panicked|ERROR: libFuzzer|SUMMARY|Test unit written|==[0-9]+==' "$log" | head -20 || true
    echo "  full log: $log; reproduce with: $bin <artifact>"
  else
    # In fork mode the count is of the jobs finished when the time ran out: a lower bound.
    echo "fuzz $t: $execs executions in ${secs} s, coverage $cov, no crash (log: $log)"
  fi
  n_slow=$(find "$artifacts" -name 'timeout-*' | wc -l)
  if [ "$n_slow" -gt 0 ]; then
    echo "  $t: $n_slow inputs (all runs so far) ran longer than the timeout: $artifacts/timeout-*"
  fi
  n_int=$(find "$findings" -name 'soft-*.txt' | wc -l)
  if [ "$n_int" -gt 0 ]; then
    echo "  $t: $n_int distinct inputs (all runs so far) broke the soft contract (the core's internal"
    echo "  error, or a power fraction > 1): $findings/*.txt (FUZZ_STRICT=1 makes them crashes)"
    for f in $(find "$findings" -name 'soft-*.txt' | sort | sed -n 1,3p); do
      echo "    $(head -c 300 "$f")"
    done
  fi
done
echo "fuzz total: $total executions over ${#targets[@]} targets"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: crashes in ${failed[*]}"
  exit 1
fi
