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
# memory-hungry inputs are written to target/fuzz/artifacts/TARGET/ and the script exits 1.
# Inputs that break only the soft contract (the core's *internal* error, BFR_INTERNAL or "a bug:
# please report the input": a clean error status, no non-finite number handed out, but a core
# defect; or a finite power fraction above 1) are kept in target/fuzz/findings/TARGET/ and
# listed; FUZZ_STRICT=1 turns them into crashes.
# libFuzzer's seed is fixed (FUZZ_SEED, default 1) so that runs are repeatable up to timing.
# Prints the executions of each target and their total.
set -euo pipefail

secs=${1:?usage: run.sh SECONDS [TARGET...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(c_abi calc_json calc_fields)
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
  # -timeout: one input running longer than FUZZ_TIMEOUT (default 60 s) is a finding (a hang;
  # single sRGB-integrated plate queries near grazing incidence are known to take 5-50 s);
  # -rss_limit_mb: a memory blow-up is one too. -max_len: documents and arguments are short.
  FUZZ_FINDINGS="$findings" "$bin" -max_total_time="$secs" -seed="${FUZZ_SEED:-1}" \
    -timeout="${FUZZ_TIMEOUT:-60}" -rss_limit_mb=2048 \
    -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts" ${dict[@]+"${dict[@]}"} \
    "$corpus" ${seeds[@]+"${seeds[@]}"} >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -E '^#[0-9]+' "$log" | tail -1 | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
  execs=${execs:-0}
  total=$((total + execs))
  if [ $rc -ne 0 ]; then
    failed+=("$t")
    echo "fuzz $t: FAILED (exit $rc) after $execs executions; input kept in $artifacts"
    grep -E 'panicked|ERROR: libFuzzer|SUMMARY|Test unit written|==[0-9]+==' "$log" | head -20 || true
    echo "  full log: $log; reproduce with: $bin <artifact>"
  else
    echo "fuzz $t: $execs executions in ${secs} s, coverage $cov, no crash (log: $log)"
  fi
  n_int=$(find "$findings" -name 'soft-*.txt' | wc -l)
  if [ "$n_int" -gt 0 ]; then
    echo "  $t: $n_int distinct inputs (all runs so far) broke the soft contract (the core's internal"
    echo "  error, or a power fraction > 1): $findings/*.txt (FUZZ_STRICT=1 makes them crashes)"
    find "$findings" -name 'soft-*.txt' | head -3 | while read -r f; do echo "    $(head -c 300 "$f")"; done
  fi
done
echo "fuzz total: $total executions over ${#targets[@]} targets"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: crashes in ${failed[*]}"
  exit 1
fi
